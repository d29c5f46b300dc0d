"""The Python package against the CLI on the same inputs, its arrays, its errors (src/python/fibernet_module.cpp,
python/fibernet/__init__.py)."""
import os
import subprocess

import numpy as np
import pytest

import fibernet as fn

SCENE = dict(L=4, q=8, pl=1, seed=3, scheme="even")


def test_generate_is_the_cli_network(tmp_path, exe):
    net = fn.generate(L=4, q=8, pl=0.6, seed=11)
    net.save(tmp_path / "py.net")
    subprocess.run([exe, "generate", "--L", "4", "--q", "8", "--pl", "0.6", "--seed", "11", "-q",
                    "-o", str(tmp_path / "cli.net")], check=True)
    assert (tmp_path / "py.net").read_bytes() == (tmp_path / "cli.net").read_bytes()
    assert net.fibers.shape == (128, 4)
    c = net.crossings
    assert c["fibers"].shape == (len(c["crosslink"]), 2)
    assert int(c["crosslink"].sum()) == net.num_crosslinks
    assert np.all(c["fibers"][:, 0] < c["fibers"][:, 1])
    back = fn.load_network(tmp_path / "py.net")
    assert np.array_equal(back.fibers, net.fibers)


def test_network_from_fibers_finds_the_same_crossings():
    net = fn.generate(L=3, q=6, pl=1, seed=2)
    again = fn.network_from_fibers(net.L, net.fibers, pl=1, seed=2)
    for key in ("fibers", "arcs", "image", "crosslink"):
        assert np.array_equal(again.crossings[key], net.crossings[key])
    with pytest.raises(ValueError, match="length = -1"):
        fn.network_from_fibers(3, [[0, 0, 0, -1]])
    with pytest.raises(ValueError, match="4 columns"):
        fn.network_from_fibers(3, np.zeros((2, 3)))


def test_discretize_is_the_cli_model(tmp_path, exe):
    m = fn.discretize(fn.generate(L=3, q=8, seed=4), scheme="even", h=0.5, a=20)
    fn.save_state(tmp_path / "py.model", m)
    subprocess.run([exe, "export", "--L", "3", "--q", "8", "--seed", "4", "--scheme", "even", "--h", "0.5",
                    "--a", "20", "-q", "-o", str(tmp_path / "cli.model")], check=True)
    assert (tmp_path / "py.model").read_bytes() == (tmp_path / "cli.model").read_bytes()
    s = m.segments
    assert s["nodes"].shape == (len(s["l0"]), 2) and s["nodes"].max() < m.num_nodes
    assert np.all(s["l0"] > 0) and np.all(s["l0"] <= 0.5 + 1e-12)
    assert m.hinges["nodes"].shape[1] == 3
    assert m.x_ref.shape == (m.num_nodes, 2)
    assert fn.energy(m)["energy"] < 1e-20  # the reference is stress-free


def test_modulus_matches_the_cli(cli):
    py = fn.modulus(**SCENE)
    code, out, _ = cli("modulus", "--L", 4, "--q", 8, "--pl", 1, "--seed", 3, "--scheme", "even", "-q")
    assert code == 0 and py["exit_code"] == 0
    for name in ("G", "K"):
        a, b = py["moduli"][name], out["moduli"][name]
        assert abs(a - b) <= py["moduli"][name + "_error"] + out["moduli"][name + "_error"]
    assert py["moduli"]["G_affine"] == out["moduli"]["G_affine"]  # no solve: the same sums
    assert py["network"] == out["network"] and py["model"] == out["model"]


def test_provenance_reruns(tmp_path, cli):
    py = fn.modulus(**SCENE)
    p = py["provenance"]
    assert p["fibernet"]["version"] == fn.__version__
    assert "seed = 3" in p["scene_toml"] and 'scheme = "even"' in p["scene_toml"]
    assert "modulus" in p["command"] and "units" in p
    (tmp_path / "again.toml").write_text(p["scene_toml"])
    code, out, _ = cli("modulus", tmp_path / "again.toml", "-q")
    assert code == 0
    assert abs(out["moduli"]["G"] - py["moduli"]["G"]) <= 2 * py["moduli"]["G_error"]


def test_relax_state_is_exact():
    r = fn.relax(**SCENE, gamma=0.05)
    assert r["status"] == "converged" and r["exit_code"] == 0
    st = r["state"]
    assert np.allclose(st.F, [[1, 0.05], [0, 1]], rtol=0, atol=0)
    e = st.energy()
    # The state in the file is lossless: it re-evaluates at the max|g| the solve reported (up to the order of
    # a parallel sum), and at the energy it reported.
    assert e["grad_max"] <= r["solver"]["grad_max"] + 1e-12
    assert e["energy"] == pytest.approx(r["energy"]["total"], rel=1e-12)
    assert e["gradient"].shape == (st.model.num_nodes, 2)


def test_elimination_is_on_by_default_and_off_with_false():
    # A switch that is on by default turns off with False (--no-eliminate), not silently left on.
    scene = dict(L=10, q=8, pl=1, seed=1, scheme="even", prune=["dangling", "ends"], gamma=0.01, tol=1e-9)
    on, off = fn.relax(**scene), fn.relax(**scene, eliminate=False)
    assert on["status"] == off["status"] == "converged"
    assert on["solver"]["local_solves"] > 0 and off["solver"]["local_solves"] == 0
    assert "eliminate = false" in off["provenance"]["scene_toml"]
    assert off["stress"]["xy"] == pytest.approx(on["stress"]["xy"], rel=1e-9)  # one minimum, both at max|g| <= 1e-9


def test_not_converged_is_a_status_not_a_state():
    r = fn.relax(**SCENE, gamma=0.2, max_iter=1)
    assert r["status"] != "converged" and r["exit_code"] == 1
    assert r["state"] is None and r["stress"] is None


def test_sweep_table_as_arrays():
    r = fn.sweep(L=3, q=8, seed=1, scheme="even", gamma_max=0.03)
    assert r["status"] == "completed"
    t = r["table"]
    assert len(t["gamma"]) == r["rows"] and t["gamma"][0] == 0 and t["gamma"][-1] == pytest.approx(0.03)
    assert np.all(np.diff(t["gamma"]) > 0)
    assert np.all(t["dsdgamma"] > 0)


def test_rigidity_and_wet():
    rg = fn.rigidity(L=4, q=8, seed=1, pl=0.5, open=True, clusters=True)
    assert len(rg["open"]["cluster_of_fiber"]) == rg["network"]["fibers"]
    assert 0 <= rg["clamped"]["d"] <= 3
    w = fn.wet(L=3, q=6, seed=1, scheme="even", betas="0,0.1", no_moduli=True)
    assert w["exit_code"] == 0 and list(w["sweep"]["beta"]) == [0, 0.1]
    assert len(w["pores"]["area"]) > 0
    for run in w["runs"]:  # the wet equilibria, exact: their energies are the dry part of the summary's
        st = run["state"]
        assert st is not None and st.u.shape == (st.model.num_nodes, 2)


@pytest.mark.parametrize("kwargs, named", [
    (dict(L=-1), "L (box side in fiber lengths) = -1"),
    (dict(scheme="odd"), "odd"),
    (dict(seed=-1), "seed -1"),
    (dict(foo=3), "unknown option foo="),
    (dict(tol=-2.5), "-2.5"),
])
def test_bad_input_is_a_value_error_naming_it(kwargs, named):
    with pytest.raises(ValueError) as e:
        fn.modulus(**kwargs)
    assert named in str(e.value)


def test_run_names_an_unknown_flag_and_the_nearest():
    # Before, the unknown flag's value was taken for the scene file ("scene: File does not exist: 8").
    with pytest.raises(ValueError, match=r"unknown flag '--density' for 'fibernet modulus' \(did you mean --q\?\)"):
        fn.run("modulus", "--L", "4", "--density", "8")


def test_bad_input_writes_nothing(tmp_path):
    out = tmp_path / "sweep.csv"
    with pytest.raises(ValueError, match="q"):
        fn.sweep(L=3, q=-8, gamma_max=0.01, output=out)
    assert not out.exists()
    with pytest.raises(ValueError, match="cannot be read"):
        fn.load_state(tmp_path / "missing.model")
    with pytest.raises(ValueError, match="rows"):
        fn.energy(fn.discretize(fn.generate(L=3, q=4)), u=np.zeros((3, 2)))


def test_state_round_trip(tmp_path):
    r = fn.relax(**SCENE, gamma=0.02)
    r["state"].save(tmp_path / "s.model")
    s = fn.load_state(tmp_path / "s.model")
    assert np.array_equal(s.u, r["state"].u) and np.array_equal(s.F, r["state"].F)
    assert np.array_equal(s.model.x_ref, r["state"].model.x_ref)


def test_sweep_progress_callback():
    lines = []
    r = fn.sweep(L=3, q=8, seed=1, scheme="even", gamma_max=0.03, progress=lines.append)
    assert r["status"] == "completed"
    assert len(lines) == r["rows"] and all(line.startswith("sweep: step") for line in lines)
    assert "ETA" in lines[1]

    def stop(line):
        raise KeyboardInterrupt("enough")
    with pytest.raises(KeyboardInterrupt):
        fn.sweep(L=3, q=8, seed=1, scheme="even", gamma_max=0.03, progress=stop)


def test_recorded_command_reruns(cli):
    """The provenance's command line, run by a shell as written, gives the same result."""
    import shlex
    py = fn.modulus(**SCENE)
    words = shlex.split(py["provenance"]["command"])
    assert words[0] == "fibernet"
    code, out, _ = cli(*words[1:])
    assert code == 0
    assert abs(out["moduli"]["G"] - py["moduli"]["G"]) <= 2 * py["moduli"]["G_error"]
    assert out["provenance"]["scene_toml"] == py["provenance"]["scene_toml"]


def test_scan_from_python_returns_its_result(tmp_path):
    """A scan runs its samples in process too: their captures nest inside the scan's."""
    code, out = fn.run("scan", "--L", 3, "--q", 6, "--open", "--scheme", "even", "--vary", "seed=1,2",
                       "--job", "rigidity", "-o", tmp_path / "sc", "-q")
    assert code == 0 and out is not None and out["samples"] == 2
    assert (tmp_path / "sc" / "samples.csv").exists()


def test_help_is_a_result():
    code, out = fn.run("modulus", "--help")
    assert code == 0 and "--gamma" in out["help"]


def test_wet_progress_callback_error_is_raised():
    def fail(line):
        raise RuntimeError("from the callback")
    with pytest.raises(RuntimeError, match="from the callback"):
        fn.wet(L=3, q=6, scheme="even", betas="0,0.1", no_moduli=True, progress=fail)
