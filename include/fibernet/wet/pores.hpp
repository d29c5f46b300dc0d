#pragma once
// Pores of a fiber network (issues 6 and 22): the faces of the planar arrangement of all fibers at their current
// positions. The arrangement is CGAL's Arrangement_2 on exact rational coordinates, so every crossing, overlap and
// face is exact and the faces tile the box: each face is classified, and nothing is left unaccounted.
//
// A periodic box is a torus. It is cut open along two lattice lines (chosen off every node), the fibers are clipped
// into the cut cell, and the cell's faces are glued back across the cut, each with its lattice offset. A glued face
// whose offsets do not close winds around the torus (`open`). Dangling fibers and free trees bound no area and are
// pruned first (repeatedly removing fiber ends of degree one on the torus), so a face is a disk exactly when its
// compactly supported Euler characteristic, counted over the glued cells, is 1; a face with islands (fiber clusters
// that touch nothing around them) inside has 1 - islands. Of the disks, those whose mean width 2 A / P (A area, P
// perimeter: the inscribed diameter for a triangle) is below the wall width lie inside a bundle or a fiber's own
// thickness: they are walls, not pores. The wall width defaults to the fiber diameter 2/a, the smooth model's
// contact distance, so fibers zipped within the contact distance make one wall.
#include <Eigen/Core>
#include <vector>

#include "fibernet/model/model.hpp"

namespace fibernet {

struct Pore {
    double area = 0;
    double diameter = 0;   // equivalent diameter sqrt(4 A / pi)
    int edges = 0;         // fiber edges of the arrangement around it
};

struct PoreStats {
    std::vector<Pore> pores;   // faces that are disks at least the wall width wide
    double box_area = 0;
    double remainder = 0;      // box area not in pores: walls + island faces + open faces (+ outside, open box)
    double wall_width = 0;     // the width below which a disk is a wall
    int walls = 0;             // disks narrower than the wall width: inside bundles, slivers between zipped fibers
    double wall_area = 0;
    int island_faces = 0;      // faces with islands inside (not disks); their net area (islands excluded)
    double island_area = 0;
    int islands = 0;           // islands inside those faces
    int open_faces = 0;        // faces that wind around the torus (the void percolates through the box)
    double open_area = 0;
    double outside_area = 0;   // open box only: the box area outside every bounded face (negative if fibers leave it)
    // The part of the box the classes above describe: pores + walls + island faces + open faces, over the box area
    // (1 to round-off on a torus: the faces tile it).
    double cover() const;
};

// The default wall width for a model: the fiber diameter 2/a (seed units).
double default_wall_width(const Model& m);

// Pores at node positions x in the box with matrix B (model units); wall_width <= 0 takes default_wall_width(m).
PoreStats pores(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, double wall_width = 0);

}  // namespace fibernet
