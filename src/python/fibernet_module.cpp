// The Python extension fibernet._fibernet (pybind11): networks, models and states as numpy arrays, the model energy,
// and the CLI's commands run in process (python/fibernet/__init__.py wraps them as functions returning dicts).
// Errors: InputError -> ValueError, OutputError -> OSError; a solver that did not converge is a result, not an error.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>

#include "common.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/model/model_io.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet_version.hpp"
#include "in_process.hpp"

namespace py = pybind11;
using namespace fibernet;

namespace {

using Rows2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;
using IntRows = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

Rows2 as_rows(const Eigen::VectorXd& v) { return Eigen::Map<const Rows2>(v.data(), v.size() / 2, 2); }

Eigen::VectorXd interleaved(const Rows2& r, Eigen::Index nodes, const char* what) {
    if (r.rows() != nodes)
        throw InputError(std::string(what) + " has " + std::to_string(r.rows()) + " rows; the model has " +
                         std::to_string(nodes) + " nodes");
    Eigen::VectorXd v(2 * r.rows());
    for (Eigen::Index i = 0; i < r.rows(); ++i) v[2 * i] = r(i, 0), v[2 * i + 1] = r(i, 1);
    return v;
}

// ---- networks ----

Eigen::MatrixXd fibers_array(const Network& n) {
    Eigen::MatrixXd a(n.fibers.size(), 4);
    for (size_t i = 0; i < n.fibers.size(); ++i)
        a.row(i) << n.fibers[i].start.x(), n.fibers[i].start.y(), n.fibers[i].theta, n.fibers[i].length;
    return a;
}

py::dict crossings_arrays(const Network& n) {
    const auto m = static_cast<Eigen::Index>(n.crossings.size());
    IntRows fibers(m, 2), image(m, 2);
    Eigen::MatrixXd arcs(m, 2);
    Eigen::Matrix<bool, Eigen::Dynamic, 1> link(m);
    for (Eigen::Index k = 0; k < m; ++k) {
        const Crossing& c = n.crossings[k];
        fibers.row(k) << c.f1, c.f2;  // one comma initializer per statement: a comma would feed the first one
        image.row(k) << c.image.x(), c.image.y();
        arcs.row(k) << c.s1, c.s2;
        link[k] = c.crosslink;
    }
    py::dict d;
    d["fibers"] = fibers, d["arcs"] = arcs, d["image"] = image, d["crosslink"] = link;
    return d;
}

// A network of given fibers (rows x0, y0, theta, length; fiber lengths), its crossings found and each made a
// crosslink with probability pl from `seed`'s stream, as the generator does.
Network network_from_fibers(double L, const Eigen::MatrixXd& fibers, bool periodic, double pl, std::uint64_t seed) {
    if (fibers.cols() != 4) throw InputError("fibers must have 4 columns (x0, y0, theta, length), not " +
                                             std::to_string(fibers.cols()));
    Network n;
    n.L = L, n.periodic = periodic, n.pl = pl, n.seed = seed;
    for (Eigen::Index i = 0; i < fibers.rows(); ++i) {
        Fiber f;
        f.start = {fibers(i, 0), fibers(i, 1)}, f.theta = fibers(i, 2), f.length = fibers(i, 3);
        if (!fibers.row(i).allFinite() || f.length <= 0)
            throw InputError("fibers row " + std::to_string(i) + ": length = " + show(f.length) +
                             " must be > 0 and every value finite");
        n.fibers.push_back(f);
    }
    std::ostringstream text;  // the file reader's checks (box, lengths against L/2, ...) apply to hand-made input too
    n.crossings = find_crossings(n);
    assign_crosslinks(n, pl, seed);
    write_network(text, n);
    std::istringstream back(text.str());
    return read_network(back, "fibers array");
}

// ---- energy ----

py::dict energy(const Model& m, const Rows2& u, const Eigen::Matrix2d& F) {
    const NetworkEnergy e(m);
    const Eigen::VectorXd uu = interleaved(u, m.num_nodes(), "u");
    const Eigen::VectorXd q = e.dofs_of_displacements(uu);
    EnergyEval ev;
    {
        py::gil_scoped_release release;
        e.evaluate(q, F, Eigen::Matrix2d::Zero(), kValue | kGradient, ev);
    }
    Eigen::VectorXd g = Eigen::VectorXd::Zero(m.x.size());  // per node; 0 at a clamped node
    for (int i = 0; i < m.num_nodes(); ++i)
        for (int c = 0; c < 2; ++c)
            if (e.dof(i, c) >= 0) g[2 * i + c] = ev.gradient[e.dof(i, c)];
    py::dict d;
    d["energy"] = ev.energy, d["stretch"] = ev.stretch, d["bend"] = ev.bend;
    d["gradient"] = as_rows(g), d["grad_max"] = ev.gradient.size() ? ev.gradient.lpNorm<Eigen::Infinity>() : 0.0;
    return d;
}

// ---- commands ----

std::mutex& command_mutex() {
    static std::mutex m;
    return m;
}

// progress: None, or a callable given each progress line (sweep steps, wet betas) while the command runs. An exception
// it raises ends the calls to it, stops a sweep after its step (as Ctrl-C does; other commands run to their end) and
// is raised again once the command has returned.
py::tuple run(const std::vector<std::string>& argv, py::object progress) {
    cli::CommandOutcome o;
    std::optional<py::error_already_set> callback_error;
    {
        py::gil_scoped_release release;
        std::lock_guard<std::mutex> lock(command_mutex());
        if (!progress.is_none())
            cli::progress_sink() = [&](const std::string& line) {
                py::gil_scoped_acquire acquire;
                if (callback_error) return;
                try {
                    progress(line);
                } catch (py::error_already_set& e) {
                    callback_error.emplace(std::move(e));
                    cli::stop_requested() = true;  // a sweep stops after this step, as on Ctrl-C
                }
            };
        struct ResetSink {
            ~ResetSink() { cli::progress_sink() = nullptr; }
        } reset;
        CLI::App app{"fibernet", "fibernet"};
        cli::register_commands(app);
        o = cli::run_command(app, argv, true);
    }
    if (callback_error) throw std::move(*callback_error);
    const py::object loads = py::module_::import("json").attr("loads");
    const py::object result = o.result.is_null() ? py::none() : loads(cli::json_text(o.result));
    return py::make_tuple(o.exit_code, result, o.error);
}

// The long flag names a command accepts (without dashes), for the package to name an unknown keyword itself.
std::vector<std::string> command_flags(const std::string& command) {
    CLI::App app{"fibernet", "fibernet"};
    cli::register_commands(app);
    const CLI::App* cmd = nullptr;
    try {
        cmd = app.get_subcommand(command);
    } catch (const CLI::OptionNotFound&) {
        throw InputError("unknown command '" + command + "'");
    }
    std::vector<std::string> names;
    for (const CLI::Option* o : cmd->get_options())
        for (const auto& l : o->get_lnames()) names.push_back(l);
    return names;
}

void bind_network(py::module_& m) {
    py::class_<Network>(m, "Network", "A Mikado network (lengths in fiber lengths; docs/formats.md, \"Network\")")
        .def_readonly("L", &Network::L)
        .def_readonly("periodic", &Network::periodic)
        .def_readonly("seed", &Network::seed)
        .def_readonly("q", &Network::q)
        .def_readonly("pl", &Network::pl)
        .def_property_readonly("fibers", &fibers_array, "(N, 4) array: x0, y0, theta, length per fiber")
        .def_property_readonly("crossings", &crossings_arrays,
                               "dict of arrays: fibers (M, 2), arcs (M, 2), image (M, 2), crosslink (M,)")
        .def_property_readonly("num_crosslinks", &Network::num_crosslinks)
        .def("save", [](const Network& n, const std::filesystem::path& path) { save_network(n, path.string()); },
             py::arg("path"), "writes the network file (docs/formats.md)")
        .def("__repr__", [](const Network& n) {
            return "<fibernet.Network L=" + show(n.L) + " fibers=" + std::to_string(n.fibers.size()) +
                   " crosslinks=" + std::to_string(n.num_crosslinks()) + ">";
        });
    m.def("_generate", [](double L, double q, double pl, std::uint64_t seed, bool periodic) {
        MikadoParams p;
        p.L = L, p.q = q, p.pl = pl, p.seed = seed, p.periodic = periodic;
        p.check("fibernet.generate");
        return generate_mikado(p);
    });
    m.def("_network_from_fibers", &network_from_fibers);
    m.def("_load_network", &load_network);
}

void bind_model(py::module_& m) {
    py::class_<Model>(m, "Model", "A discretized network in seed units (docs/formats.md, \"Model\")")
        .def_property_readonly("L", [](const Model& md) { return md.box.L; })
        .def_property_readonly("periodic", [](const Model& md) { return md.box.periodic; })
        .def_readonly("aspect_ratio", &Model::aspect_ratio)
        .def_readonly("fiber_length", &Model::fiber_length)
        .def_property_readonly("x_ref", [](const Model& md) { return as_rows(md.x); }, "(n, 2) reference positions")
        .def_property_readonly("fixed", [](const Model& md) {
            Eigen::Matrix<bool, Eigen::Dynamic, 1> f = Eigen::Matrix<bool, Eigen::Dynamic, 1>::Zero(md.num_nodes());
            for (int i = 0; i < md.num_nodes() && !md.fixed.empty(); ++i) f[i] = md.fixed[i];
            return f;
        })
        .def_property_readonly("segments", [](const Model& md) {
            const auto n = static_cast<Eigen::Index>(md.segments.size());
            IntRows nodes(n, 2), shift(n, 2);
            Eigen::VectorXd l0(n);
            Eigen::VectorXi fiber(n);
            for (Eigen::Index k = 0; k < n; ++k) {
                const Segment& s = md.segments[k];
                nodes.row(k) << s.i, s.j;
                shift.row(k) << s.shift.x(), s.shift.y();
                l0[k] = s.l0, fiber[k] = s.fiber;
            }
            py::dict d;
            d["nodes"] = nodes, d["shift"] = shift, d["l0"] = l0, d["fiber"] = fiber;
            return d;
        }, "dict of arrays: nodes (m, 2), shift (m, 2) image of node j, l0 (m,), fiber (m,)")
        .def_property_readonly("hinges", [](const Model& md) {
            const auto n = static_cast<Eigen::Index>(md.hinges.size());
            IntRows nodes(n, 3);
            Eigen::VectorXd lt0(n);
            Eigen::VectorXi fiber(n);
            for (Eigen::Index k = 0; k < n; ++k) {
                const Hinge& h = md.hinges[k];
                nodes.row(k) << h.i, h.j, h.k;
                lt0[k] = h.lt0, fiber[k] = h.fiber;
            }
            py::dict d;
            d["nodes"] = nodes, d["lt0"] = lt0, d["fiber"] = fiber;
            return d;
        }, "dict of arrays: nodes (h, 3) bend at the middle one, lt0 (h,), fiber (h,)")
        .def_property_readonly("supernodes", [](const Model& md) {
            Eigen::VectorXi n(md.supernodes.size());
            for (size_t k = 0; k < md.supernodes.size(); ++k) n[k] = md.supernodes[k].node;
            return n;
        }, "(s,) node index of each crosslink")
        .def_property_readonly("num_nodes", &Model::num_nodes)
        .def("__repr__", [](const Model& md) {
            return "<fibernet.Model nodes=" + std::to_string(md.num_nodes()) + " segments=" +
                   std::to_string(md.segments.size()) + " hinges=" + std::to_string(md.hinges.size()) + ">";
        });
    m.def("_discretize", [](const Network& n, const std::string& scheme, int n_seg, double h, double a,
                            double fiber_length) {
        DiscretizationParams p;
        p.scheme = parse_scheme(scheme), p.n_seg = n_seg, p.h = h, p.aspect_ratio = a, p.fiber_length = fiber_length;
        p.check("fibernet.discretize");
        return discretize(n, p);
    });
    m.def("_load_model", [](const std::string& path) {
        std::ifstream in(path);
        if (!in) throw InputError(path + ": cannot be read");
        Eigen::VectorXd u;
        Eigen::Matrix2d F;
        Model md = read_model(in, path, &u, &F);
        return py::make_tuple(md, as_rows(u), F);
    });
    m.def("_save_model", [](const std::string& path, const Model& md, const Rows2& u, const Eigen::Matrix2d& F) {
        std::ostringstream os;
        write_model(os, md, interleaved(u, md.num_nodes(), "u"), F);
        write_file_atomic(path, os.str());
    });
    m.def("_energy", &energy);
}

}  // namespace

PYBIND11_MODULE(_fibernet, m) {
    m.doc() = "fibernet's C++ core (use the fibernet package, python/fibernet/__init__.py)";
    m.attr("__version__") = FIBERNET_VERSION;
    m.attr("commit") = FIBERNET_GIT_COMMIT;
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const OutputError& e) {
            PyErr_SetString(PyExc_OSError, e.what());
        }
    });
    bind_network(m);
    bind_model(m);
    m.def("_flags", &command_flags);
    m.def("_run", &run, py::arg("argv"), py::arg("progress") = py::none(), "runs `fibernet argv...` in process: (exit code, JSON result or None, internal error text)");
}
