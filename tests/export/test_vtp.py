"""fibernet export --format vtp and sweep --vtk, read by VTK's own reader (Debian python3-vtk9): the fields are the
model's (src/export/vtp.cpp)."""
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from vtk.util.numpy_support import vtk_to_numpy
import vtk

import fibernet as fn


def read_vtp(path):
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(path))
    r.Update()
    out = r.GetOutput()
    assert out.GetNumberOfCells() > 0, f"VTK read no cells from {path}"
    cells = {out.GetCellData().GetArrayName(i): vtk_to_numpy(out.GetCellData().GetArray(i))
             for i in range(out.GetCellData().GetNumberOfArrays())}
    points = {out.GetPointData().GetArrayName(i): vtk_to_numpy(out.GetPointData().GetArray(i))
              for i in range(out.GetPointData().GetNumberOfArrays())}
    field = {out.GetFieldData().GetArrayName(i): out.GetFieldData().GetArray(i).GetValue(0)
             for i in range(out.GetFieldData().GetNumberOfArrays())}
    return out, cells, points, field


def test_vtp_of_a_relaxed_state(tmp_path, cli):
    code, relax, _ = cli("relax", "--L", 3, "--q", 8, "--seed", 2, "--scheme", "even", "--gamma", 0.05, "-q",
                         "-o", tmp_path / "state.model")
    assert code == 0
    code, _, err = cli("export", "--model", tmp_path / "state.model", "--format", "vtp", "-o", tmp_path / "s.vtp", "-q")
    assert code == 0, err
    poly, cells, points, _ = read_vtp(tmp_path / "s.vtp")
    st = fn.load_state(tmp_path / "state.model")
    seg = st.model.segments
    assert poly.GetNumberOfLines() == len(seg["l0"])
    assert np.array_equal(cells["fiber"], seg["fiber"])
    # The cells' energies add up to the state's: each hinge split between its two segments.
    e = relax["energy"]
    assert cells["stretch_energy"].sum() == pytest.approx(e["stretch"], rel=1e-12)
    assert cells["bend_energy"].sum() == pytest.approx(e["bend"], rel=1e-12)
    # Strain from the drawn points: every segment is drawn unwrapped, at its own length.
    pts = vtk_to_numpy(poly.GetPoints().GetData())[:, :2]
    lengths = np.linalg.norm(pts[1::2] - pts[0::2], axis=1)
    assert np.allclose(lengths / seg["l0"] - 1, cells["strain"], rtol=0, atol=1e-9)
    assert lengths.max() < 0.5 * st.model.L  # none drawn across the periodic box
    # Point data: each point's node and its displacement.
    assert np.array_equal(points["node"][0::2], seg["nodes"][:, 0])
    assert np.allclose(points["displacement"][:, :2], st.u[points["node"]], rtol=0, atol=0)
    assert set(np.unique(points["crosslink"])) <= {0, 1}
    assert points["crosslink"][np.isin(points["node"], st.model.supernodes)].all()


def test_vtp_of_an_open_box_carries_rigid_clusters(tmp_path, cli):
    code, _, err = cli("export", "--L", 3, "--q", 8, "--pl", 0.7, "--open", "--format", "vtp",
                       "-o", tmp_path / "o.vtp", "-q")
    assert code == 0, err
    _, cells, _, _ = read_vtp(tmp_path / "o.vtp")
    code, rig, _ = cli("rigidity", "--L", 3, "--q", 8, "--pl", 0.7, "--open", "--clusters", "-q")
    clusters = np.array(rig["open"]["cluster_of_fiber"])
    assert np.array_equal(cells["rigid_cluster"], clusters[cells["fiber"]])


def test_sweep_series(tmp_path, cli):
    code, out, err = cli("sweep", "--L", 3, "--q", 8, "--scheme", "even", "--gamma-max", 0.03, "-q",
                         "-o", tmp_path / "s.csv", "--vtk", tmp_path / "vtk")
    assert code == 0, err
    gammas = np.loadtxt(tmp_path / "s.csv", delimiter=",", skiprows=1, usecols=1, ndmin=1)
    steps = ET.parse(tmp_path / "vtk" / "series.pvd").getroot().find("Collection").findall("DataSet")
    assert [float(d.get("timestep")) for d in steps] == list(gammas)
    for d, g in zip(steps, gammas):
        _, _, _, field = read_vtp(tmp_path / "vtk" / d.get("file"))
        assert field["gamma"] == g and "dsdgamma" in field


def test_wet_state_with_bridges(tmp_path, cli):
    code, out, err = cli("wet", "--L", 3, "--q", 6, "--scheme", "even", "--betas", 0.1, "--no-moduli", "-q",
                         "-o", tmp_path / "wet")
    assert code == 0, err
    run = out["runs"][0]
    poly, cells, points, field = read_vtp(tmp_path / "wet" / "state_0.vtp")
    nb = run["bridges"]["final"]
    assert poly.GetNumberOfVerts() == nb and nb > 0
    assert set(cells["bridge"][:nb]) <= {1, 2} and not cells["bridge"][nb:].any()
    assert (cells["fiber"][:nb] == -1).all() and (cells["fiber"][nb:] >= 0).all()
    assert field["beta"] == 0.1
    # The fibers' part of the wet energy, cell by cell.
    assert cells["stretch_energy"].sum() == pytest.approx(run["energy"]["wet"]["stretch"], rel=1e-9)
    assert cells["bend_energy"].sum() == pytest.approx(run["energy"]["wet"]["bend"], rel=1e-9)
    # The model-file state beside it is the same equilibrium.
    st = fn.load_state(tmp_path / "wet" / run["state"])
    e = st.energy()
    assert e["stretch"] == pytest.approx(run["energy"]["wet"]["stretch"], rel=1e-12)
