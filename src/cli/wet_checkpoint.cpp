#include "wet_checkpoint.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/model_io.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/util/hash.hpp"
#include "fibernet/util/stopwatch.hpp"

namespace fibernet::cli {

namespace {
namespace fs = std::filesystem;


std::string matrix_text(const Eigen::Matrix2d& M) {
    char b[160];
    std::snprintf(b, sizeof b, "[[%.17g, %.17g], [%.17g, %.17g]]", M(0, 0), M(0, 1), M(1, 0), M(1, 1));
    return b;
}

std::string canonical(const std::string& path) {
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(path, ec);
    return ec ? path : p.string();
}

// The JSON beside a state file: checkpoint_3.txt -> checkpoint_3.json.
std::string sidecar(const std::string& state) { return fs::path(state).replace_extension(".json").string(); }

// This command without its betas and start state, to which a checkpoint's JSON adds its own.
std::string continued_command(const std::vector<std::string>& argv) {
    std::string line = "fibernet";
    for (size_t i = 0; i < argv.size(); ++i) {
        const std::string& a = argv[i];
        bool dropped = false;
        for (const char* flag : {"--betas", "--beta", "--start-state"}) {
            const std::string f = flag;
            if (a == f) dropped = true, ++i;  // and its value
            else if (a.rfind(f + "=", 0) == 0) dropped = true;
        }
        if (!dropped) line += " " + shell_quoted(a);
    }
    return line;
}
}  // namespace

StartState read_start_state(const std::string& path, const Model& m, const Eigen::Matrix2d& F) {
    const std::string where = "--start-state '" + path + "'";
    const std::string bytes = file_bytes(path, "--start-state: state file");
    std::istringstream is(bytes);
    Eigen::VectorXd u;
    Eigen::Matrix2d Fs = Eigen::Matrix2d::Identity();
    const Model ms = read_model(is, where, &u, &Fs);
    // The same model: its reference data written out agree byte for byte (the format round-trips exactly).
    std::ostringstream a, b;
    write_model(a, m);
    write_model(b, ms);
    if (a.str() != b.str())
        throw InputError(where + ": its model (" + std::to_string(ms.num_nodes()) + " nodes, " +
                         std::to_string(ms.segments.size()) + " segments) is not this run's (" +
                         std::to_string(m.num_nodes()) + " nodes, " + std::to_string(m.segments.size()) +
                         " segments, or the same counts with other positions, lengths or box): another network, "
                         "discretization or prune rule");
    if (Fs != F)
        throw InputError(where + ": written at box deformation F = " + matrix_text(Fs) + ", this run's is " +
                         matrix_text(F) + " (--strain, --gamma)");
    if (u.size() != m.x.size() || !u.allFinite())
        throw InputError(where + ": its state is not a finite displacement of every node");
    StartState s;
    s.q = NetworkEnergy(m).dofs_of_displacements(u);
    s.path = path;
    s.canonical = canonical(path);
    s.record = {{"file", path}, {"fnv1a", fnv1a_bytes(bytes)}};
    // How far the runs before got (the checkpoint's JSON, if it is beside the state); informative only.
    std::ifstream js(sidecar(path));
    if (js) {
        try {
            const nlohmann::json j = nlohmann::json::parse(js);
            if (j.value("fibernet_checkpoint", "") == "wet") {
                s.iterations_before = j.at("iterations_total").get<long>();
                s.seconds_before = j.at("seconds_total").get<double>();
                s.record["checkpoint"] = sidecar(path);
                s.record["beta"] = j.at("beta");
            }
        } catch (const std::exception& e) {
            std::fprintf(stderr, "wet: note: '%s' beside the start state is not a checkpoint's JSON (%s); its counts "
                         "are not carried over\n", sidecar(path).c_str(), e.what());
        }
    }
    s.record["iterations_before"] = s.iterations_before;
    s.record["seconds_before"] = s.seconds_before;
    return s;
}

WetCheckpoints::WetCheckpoints(std::string dir, double every, const Model& m, const Eigen::Matrix2d& F,
                               nlohmann::json record, const std::vector<std::string>& argv, const StartState* start,
                               bool progress, std::function<void(const std::function<void()>&)> guard)
    : dir_(std::move(dir)), every_(every), m_(m), F_(F), record_(std::move(record)), hint_(continued_command(argv)),
      start_(start), progress_(progress), guard_(std::move(guard)) {}

void WetCheckpoints::begin(size_t k, double beta) {
    k_ = k, beta_ = beta, iterations_ = 0, written_ = false;
    t0_ = last_ = std::chrono::steady_clock::now();
}

void WetCheckpoints::observe(const Eigen::VectorXd& q, double energy, double grad_max) {
    ++iterations_;
    if (!enabled() || seconds_since(last_) < every_) return;
    write(q, energy, grad_max, false);
}

void WetCheckpoints::observe_within(const Eigen::VectorXd& q, const std::function<double()>& energy) {
    if (!enabled() || seconds_since(last_) < every_) return;
    write(q, energy(), std::nullopt, false);
}

std::string WetCheckpoints::keep_last(const Eigen::VectorXd& q, double energy, double grad_max) {
    if (!enabled()) return "";
    write(q, energy, grad_max, true);
    return "checkpoint_" + std::to_string(k_) + ".txt";
}

void WetCheckpoints::discard() const {
    if (!enabled()) return;
    const std::string name = dir_ + "checkpoint_" + std::to_string(k_);
    std::error_code ec;
    for (const std::string& f : {name + ".txt", name + ".json"})
        if (written_ || !kept(f)) fs::remove(f, ec);  // a start state this run overwrote is its own checkpoint
}

void WetCheckpoints::remove_stale() const {
    if (dir_.empty()) return;
    std::error_code ec;
    std::vector<std::string> stale;
    for (const auto& f : fs::directory_iterator(dir_, ec)) {
        const std::string n = f.path().filename().string();
        const std::string ext = f.path().extension().string();
        if (n.rfind("checkpoint_", 0) == 0 && (ext == ".txt" || ext == ".json") && !kept(dir_ + n))
            stale.push_back(dir_ + n);
    }
    for (const std::string& f : stale) {
        fs::remove(f, ec);
        if (ec) throw InputError("--out-dir: cannot remove the previous " + f + " (" + ec.message() + ")");
    }
}

bool WetCheckpoints::kept(const std::string& file) const {
    if (!start_) return false;
    const std::string c = canonical(file);
    return c == start_->canonical || c == canonical(sidecar(start_->path));
}

void WetCheckpoints::write(const Eigen::VectorXd& q, double energy, std::optional<double> grad_max, bool last) {
    const std::string stem = "checkpoint_" + std::to_string(k_);
    const bool within = !grad_max;
    const double seconds = seconds_since(t0_);
    const long before_it = start_ ? start_->iterations_before : 0;
    const double before_s = start_ ? start_->seconds_before : 0;
    std::ostringstream state;
    const NetworkEnergy e(m_);
    write_model(state, m_, e.displacements(q, F_), F_);
    char beta[32];  // the shortest text that reads back as beta
    for (int digits = 15; digits <= 17; ++digits) {
        std::snprintf(beta, sizeof beta, "%.*g", digits, beta_);
        if (std::strtod(beta, nullptr) == beta_) break;
    }
    const nlohmann::json j = {
        {"fibernet_checkpoint", "wet"},
        {"state", stem + ".txt"},
        {"beta", beta_},
        {"beta_index", k_},
        {"last", last},  // true: the relaxation ended here unconverged; false: it was still running
        {"converged", false},
        {"energy", energy},
        {"grad_max", within ? nlohmann::json() : nlohmann::json(*grad_max)},
        {"within_iteration", within},  // true: between the local solves after iterate `iterations` (its gradient unknown)
        {"iterations", iterations_},
        {"seconds", seconds},
        {"iterations_total", before_it + iterations_},  // with the runs this one continued (--start-state)
        {"seconds_total", before_s + seconds},
        {"start_state", start_ ? start_->record : nlohmann::json()},
        {"continue_with", hint_ + " --betas " + beta + " --start-state " + shell_quoted(dir_ + stem + ".txt")},
        {"run", record_},
        {"provenance", provenance()}};
    guard_([&] {
        // The state first, its JSON last: a JSON never describes a state that is not written yet.
        write_file_atomic(dir_ + stem + ".txt", state.str());
        write_file_atomic(dir_ + stem + ".json", json_text(j, 2) + "\n");
    });
    last_ = std::chrono::steady_clock::now();
    written_ = true;
    if (progress_ && !last && within)
        std::fprintf(stderr, "wet: checkpoint after iteration %ld, within the next one's local solves (E = %.10g): %s%s.txt\n",
                     iterations_, energy, dir_.c_str(), stem.c_str());
    else if (progress_ && !last)
        std::fprintf(stderr, "wet: checkpoint at iteration %ld (E = %.10g, max|g| = %.3g): %s%s.txt\n", iterations_,
                     energy, *grad_max, dir_.c_str(), stem.c_str());
}

}  // namespace fibernet::cli
