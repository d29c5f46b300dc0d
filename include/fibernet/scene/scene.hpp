#pragma once
// A scene (docs/formats.md, "scene"; files in problems/) says what is asked: which network, how to discretize it,
// what load, which solver. TOML; every key is optional and has the default shown in docs/formats.md.
// Command-line flags override a scene's values.
#include <cstdint>
#include <string>
#include <vector>

#include "fibernet/box/box.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/model/prune.hpp"
#include "fibernet/network/mikado.hpp"

namespace fibernet {

struct SolverSettings {
    std::string name = "newton";
    double tol = 1e-10;        // max |gradient| in seed units
    int max_iter = 500;
    // Newton's nonlinear elimination (solve/nonlinear_elimination.hpp) in the dry solves (relax, modulus, sweep): on by
    // default since it reaches the same equilibria with 2-10x fewer global factorizations (docs/solvers.md); solvers
    // without it ignore the key. The wet relaxation has its own, [wet] newton_eliminate.
    bool eliminate = true;
};

// [wet] (docs/formats.md, "Wet scenes"; issue 6): capillary bridges for `fibernet wet`. Plain values here; the wet
// module (include/fibernet/wet/) interprets them.
struct WetSettings {
    double beta = 1;            // adhesion energy per unit length of a two-fiber bundle (>= 0)
    std::string law;            // tabulated law file "alpha_deg value" (empty: E = -beta l cos^2 alpha)
    std::string crossings = "all";  // which crossings are wet: all | free | fraction
    double fraction = 1;        // crossings = "fraction": probability that a crossing is wet, in [0, 1]
    std::uint64_t seed = 1;     // draws of the wet fraction
    bool free_box = false;      // after the fixed-box relaxation, find the zero-stress box (docs/wet.md, "Free box")
    std::string free_box_shape = "isotropic";  // isotropic (F = s F0) | full (symmetric U, 3 unknowns)
    double free_box_tol = 1e-3;           // |sigma| / sigma_c below which the free box has converged, > 0
    int max_rounds = 1000;      // active-set rounds (bridge-set updates) per relaxation, >= 1
    int round_iterations = 10;  // Newton iterations per round while the set changes (0: solve each round to the end)
    bool newton_ldl = true;     // Newton's first rung by LDL^T with flipped negative pivots (docs/wet.md)
    bool newton_projected = false;  // smooth model: projected Newton (SolverOptions::projected) instead of newton_ldl
    // Newton's nonlinear elimination in the wet relaxation: off, since on a landscape with many minima (zipping) it
    // commits the hot places to their nearest valley and gains nothing on the event model (docs/solvers.md).
    bool newton_eliminate = false;
    // The smooth model's elimination: hops the hot set grows by (EliminationOptions::hops; the dry default of 16 grows
    // a wet hot set past the quarter of the coordinates where elimination stands aside).
    int eliminate_hops = 2;
    // Newton's Schwarz sweep in the wet relaxation (EliminationOptions::block, overlap): before each global step every
    // coordinate is relaxed, in connected blocks of about schwarz_block coordinates grown by schwarz_overlap hops
    // (0: off; > 0 implies newton_eliminate in that form; docs/wet.md, "The Schwarz sweep").
    int schwarz_block = 0;
    int schwarz_overlap = 4;
    // Local rounds (docs/wet.md, "Local rounds"): the part of the network that needs a solve, if it holds at most
    // local_fraction of the coordinates (0: every round global); hot: |g| > local_threshold x max|g|, grown by local_hops.
    double local_fraction = 0.25;
    double local_threshold = 0.1;
    int local_hops = 3;
    // Excluded volume in bundles: a segment adheres along at most this many other fibers (0: no cap; 2: flat ribbon,
    // 6: close-packed; ActiveSetOptions::bundle_partners, docs/wet.md "Bundle partners").
    int bundle_partners = 0;
    // The capillary model (docs/wet.md, "The smooth model"; issue 22): "events" (bridges moved, formed and ruptured by
    // the active-set loop) or "smooth" (one C2 energy over all segment pairs within range, no events).
    std::string model = "events";
    // Smooth model: the distance over which a crossing passes from one segment to the next, the contact distance of
    // aligned fibers, and the neighbour list's skin (seed units; 0: the fiber radius 1/a and diameter 2/a).
    double crossing_width = 0;
    double contact_distance = 0;
    double skin = 0.5;
    double checkpoint_seconds = 300;  // smooth model with -o: the wet relaxation's state written this often; 0: never
    std::string start_state;          // smooth model: the wet relaxation starts from this state file (one beta)
};

struct Scene {
    std::string source = "defaults";  // where the values came from (file name), for messages
    MikadoParams mikado;               // used unless network_file is set
    std::string network_file;          // a saved network (fibernet generate) instead of a generated one
    DiscretizationParams discretization;
    PruneOptions prune;
    StrainKind strain = StrainKind::Shear;
    double gamma = 0;                  // strain parameter t of F(t)
    SolverSettings solver;
    WetSettings wet;

    void check() const;         // throws InputError naming the bad value and the scene's source
    void check_values() const;  // each value alone (parse_scene); check() adds their combinations (load, wet fraction)
    // beta in [0, 4 a^2] (energy/capillary.hpp, kMaxBetaOverStretch); the message is "<where>: <name> = <beta> ...".
    void check_beta(double beta, const std::string& where, const std::string& name) const;
};

// Parses a TOML scene; unknown tables/keys and wrong types are InputErrors naming file and key.
Scene load_scene(const std::string& path);
Scene parse_scene(const std::string& toml_text, const std::string& source);

// The network the scene describes (generated or loaded), pruned as asked.
Network scene_network(const Scene& s);

}  // namespace fibernet
