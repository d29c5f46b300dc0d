"""fibernet: mechanics of random fiber networks by implicit energy minimization (docs/python.md).

Networks, models and states are numpy arrays; the jobs are the command-line tool's own commands, run in this process
(with the GIL released), returning the JSON the CLI prints as a dict, plus arrays where the job has them.

    import fibernet as fn
    r = fn.modulus(L=4, q=8, pl=1, seed=1, scheme="even")
    r["G"], r["G_error"], r["G_affine"]

Every scene key is a keyword (L, q, pl, seed, open, scheme, n_seg, h, a, prune, gamma, strain, solver, tol,
max_iter, eliminate; docs/formats.md "Scene"), and so is every flag of the command (underscores for dashes: gamma_max=0.1
for --gamma-max). A scene file may be given first. Bad input raises ValueError naming the value and writes
nothing. A solve that did not converge is not an error: the result's "status" says so, and its state is None.
"""
import csv
import os
import tempfile

import numpy as np

from . import _fibernet as _core

__all__ = ["Network", "Model", "State", "FibernetError", "generate", "network_from_fibers", "load_network",
           "discretize", "load_state", "save_state", "energy", "run", "modulus", "relax", "rigidity", "sweep", "wet",
           "info", "__version__", "commit"]

Network = _core.Network
Model = _core.Model
__version__ = _core.__version__
commit = _core.commit


class FibernetError(RuntimeError):
    """An internal error of fibernet (the CLI's exit code 3): a bug to report, not bad input."""


class State:
    """A model in a state: displacements u (n, 2) from the reference x_ref, at box deformation F (2, 2)."""

    def __init__(self, model, u=None, F=None):
        self.model = model
        self.u = np.zeros((model.num_nodes, 2)) if u is None else np.asarray(u, dtype=float)
        self.F = np.eye(2) if F is None else np.asarray(F, dtype=float)

    @property
    def x(self):
        """Current node positions x_ref + u (rounded; u is the exact state)."""
        return self.model.x_ref + self.u

    def energy(self):
        return energy(self.model, self.u, self.F)

    def save(self, path):
        save_state(path, self.model, self.u, self.F)

    def __repr__(self):
        return f"<fibernet.State {self.model!r} F={self.F.tolist()}>"


# ---- networks, models, states -------------------------------------------------------------------------------------

def generate(L=10, q=8, pl=1, seed=1, periodic=True):
    """A Mikado network: round(q L^2) unit fibers in an L x L box, crossings crosslinked with probability pl.
    The same seed gives the same network as `fibernet generate` on any machine."""
    return _core._generate(float(L), float(q), float(pl), _seed(seed), bool(periodic))


def network_from_fibers(L, fibers, periodic=True, pl=1, seed=1):
    """A network of given fibers: an (N, 4) array of x0, y0, theta, length (fiber lengths)."""
    return _core._network_from_fibers(float(L), np.asarray(fibers, dtype=float), bool(periodic), float(pl),
                                      _seed(seed))


def load_network(path):
    return _core._load_network(os.fspath(path))


def discretize(network, scheme="seed", n_seg=10, h=1.0, a=10, fiber_length=10):
    """The elastic model of a network (seed units: a fiber has length fiber_length)."""
    return _core._discretize(network, str(scheme), int(n_seg), float(h), float(a), float(fiber_length))


def load_state(path):
    """A model file (fibernet export / relax -o) as a State."""
    model, u, F = _core._load_model(os.fspath(path))
    return State(model, u, F)


def save_state(path, model, u=None, F=None):
    s = State(model, u, F)
    _core._save_model(os.fspath(path), s.model, s.u, s.F)


def energy(model, u=None, F=None):
    """The model energy at displacements u and deformation F: energy, stretch, bend, gradient (n, 2; 0 at clamped
    nodes) and grad_max."""
    s = State(model, u, F)
    return _core._energy(s.model, s.u, s.F)


# ---- the commands -------------------------------------------------------------------------------------------------

_FLAG_NAMES = {"n_seg": "--nseg", "network_file": "--network"}


def _seed(seed):
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) < 2 ** 64:
        raise ValueError(f"seed = {seed!r} must be an integer in [0, 2^64)")
    return int(seed)


def _argv(command, scene, options):
    known = set(_core._flags(command))
    for key in options:
        if _FLAG_NAMES.get(key, "--" + key.replace("_", "-"))[2:] not in known:
            shown = {"nseg": "n_seg"}  # network= is the keyword for --network
            raise ValueError(f"fibernet.{command}: unknown option {key}= (expected one of: "
                             + ", ".join(sorted(shown.get(k, k.replace("-", "_")) for k in known if k != "help"))
                             + ")")
    argv = [command]
    if scene is not None:
        argv.append(os.fspath(scene))
    for key, value in options.items():
        flag = _FLAG_NAMES.get(key, "--" + key.replace("_", "-"))
        if value is False and "no-" + flag[2:] in known:  # a switch that is on by default: eliminate=False
            argv.append("--no-" + flag[2:])
            continue
        if value is None or value is False:
            continue
        if value is True:
            argv.append(flag)
        elif isinstance(value, (list, tuple)):
            argv.append(flag)
            argv.extend(str(v) for v in value)
        elif isinstance(value, float):
            argv += [flag, repr(value)]
        else:
            argv += [flag, os.fspath(value) if isinstance(value, os.PathLike) else str(value)]
    return argv


def run(command, *args, progress=None):
    """Runs `fibernet command args...` in this process: (exit code, the JSON result as a dict or None).
    Exit codes as the CLI's: 0 success, 1 not converged / failed, 130 interrupted. progress: a callable given each
    progress line (sweep steps with their ETA, wet betas) instead of stderr."""
    code, result, error = _core._run([command, *map(str, args)], progress)
    if code == 3:
        raise FibernetError(error)
    return code, result


def _network_option(tmp, network, options):
    """network: a Network (saved to tmp for the command) or a network file's path."""
    if isinstance(network, Network):
        path = os.path.join(tmp, "network.txt")
        network.save(path)
        network = path
    if network is not None:
        options["network_file"] = os.fspath(network)


def _job(command, scene, network, options):
    with tempfile.TemporaryDirectory(prefix="fibernet-") as tmp:
        _network_option(tmp, network, options)
        return _job_in(command, scene, options)


def _job_in(command, scene, options):
    progress = options.pop("progress", None)
    if not options.get("verbose") and progress is None:
        options.setdefault("quiet", True)  # progress lines go to the process's stderr, not to a notebook
    code, result = run(*_argv(command, scene, options), progress=progress)
    if result is None:
        raise FibernetError(f"fibernet {command} gave no result (exit code {code})")
    result["exit_code"] = code
    return result


def info(scene=None, *, network=None, **options):
    """Network and model statistics (fibernet info)."""
    return _job("info", scene, network, options)


def modulus(scene=None, *, network=None, **options):
    """Linear shear and bulk moduli G, K with their error bounds and affine values (fibernet modulus)."""
    return _job("modulus", scene, network, options)


def rigidity(scene=None, *, network=None, **options):
    """Pebble-game rigidity (fibernet rigidity); clusters=True adds every fiber's rigid cluster."""
    return _job("rigidity", scene, network, options)


def relax(scene=None, *, network=None, **options):
    """The equilibrium at the scene's strain (fibernet relax): the JSON (stress, energy split, solver) and, if it
    converged, result["state"], a State whose u is the exact solution."""
    with tempfile.TemporaryDirectory(prefix="fibernet-") as tmp:
        _network_option(tmp, network, options)
        out = os.path.join(tmp, "state.txt")
        result = _job_in("relax", scene, dict(options, output=out))
        result["state"] = load_state(out) if os.path.exists(out) else None
        result["output"] = None
        return result


def _read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return {}
    table = {}
    for key in rows[0]:
        try:
            table[key] = np.array([float(r[key]) if r[key] != "" else np.nan for r in rows])
        except ValueError:
            table[key] = np.array([r[key] for r in rows])
    return table


def sweep(scene=None, *, network=None, **options):
    """A quasistatic strain sweep (fibernet sweep; gamma_max is required): the JSON and result["table"], the CSV's
    columns as numpy arrays (one entry per accepted step). progress=callable gets each step's progress line."""
    with tempfile.TemporaryDirectory(prefix="fibernet-") as tmp:
        _network_option(tmp, network, options)
        out = os.fspath(options.pop("output", os.path.join(tmp, "sweep.csv")))
        result = _job_in("sweep", scene, dict(options, output=out))
        result["table"] = _read_csv(out) if os.path.exists(out) else {}
        return result


def wet(scene=None, *, network=None, **options):
    """A wet network (fibernet wet): the summary and result["sweep"], result["pores"], the CSV tables as arrays; each
    result["runs"][k]["state"] is beta k's wet equilibrium as a State (None where it did not converge).
    out_dir keeps the files (SVGs, CSVs, summary.json); by default they go to a temporary directory."""
    with tempfile.TemporaryDirectory(prefix="fibernet-") as tmp:
        _network_option(tmp, network, options)
        out = os.fspath(options.pop("out_dir", os.path.join(tmp, "wet")))
        result = _job_in("wet", scene, dict(options, out_dir=out))
        for name in ("sweep", "pores"):
            p = os.path.join(out, name + ".csv")
            result[name] = _read_csv(p) if os.path.exists(p) else {}
        for run in result.get("runs", []):  # each beta's wet equilibrium, where it converged
            run["state"] = load_state(os.path.join(out, run["state"])) if run.get("state") else None
        return result
