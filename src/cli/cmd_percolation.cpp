// fibernet percolation: rigidity (d = 0) and connectivity spanning probabilities P(q) of clamped open Mikado
// networks for a list of box sizes L (issue 4 part 4, seed figure 3.6). Samples run on --threads threads; each
// finished sample is appended to the CSV at once, so an interrupted run keeps its work and --resume continues
// it (rows are keyed by L, q and sample number, and every sample's seed derives from them). Then the
// inflection point q_1/2(L) is fitted per L (probit, binomial likelihood) and q_1/2(L) = q_c + A L^(-1/nu);
// nu also from the probit widths, width(L) = c L^(-1/nu), and q_c with nu held at that estimate.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <charconv>
#include <map>
#include <memory>
#include <optional>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>
#include <vector>

#include "common.hpp"
#include "scan_comm.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/rigidity/percolation.hpp"
#include "fibernet/rigidity/percolation_fit.hpp"

namespace fibernet::cli {

namespace {
const char* kPercolationHeader = "pl,L,q,sample,seed,fibers,d,rigid_spanning,connected_spanning,seconds";

std::string fmt(double v) {
    char b[64];
    std::snprintf(b, sizeof b, "%.10g", v);
    return b;
}

std::string csv_line(const PercolationSample& s) {
    std::ostringstream os;
    os << fmt(s.pl) << ',' << fmt(s.L) << ',' << fmt(s.q) << ',' << s.sample << ',' << s.seed << ',' << s.fibers << ','
       << s.d << ',' << s.rigid << ',' << s.connected << ',' << fmt(s.seconds) << '\n';
    return os.str();
}

using Key = std::tuple<std::string, std::string, int>;  // L, q as written, sample

// Splits a CSV row into the 10 fields csv_line writes, each parsed whole: integers in range of their type (sscanf's
// %d wrapped 4294967296 to 0), decimals as written. False for a line that is not such a row (an interrupted write).
bool parse_row(const std::string& line, PercolationSample& s, std::uint64_t& seed, int& rigid, int& conn) {
    std::vector<std::string> f;
    std::istringstream is(line);
    for (std::string x; std::getline(is, x, ',');) f.push_back(x);
    if (f.size() != 10) return false;
    auto real = parse_decimal;
    auto whole = [](const std::string& t, auto& v) {
        const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
        return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
    };
    return real(f[0], s.pl) && real(f[1], s.L) && real(f[2], s.q) && whole(f[3], s.sample) && whole(f[4], seed) &&
           whole(f[5], s.fibers) && whole(f[6], s.d) && whole(f[7], rigid) && whole(f[8], conn) && real(f[9], s.seconds);
}

// Refuses a row that percolation_sample cannot have written (at: "file:line: ").
void check_row(const PercolationSample& s, int rigid, int conn, const std::string& at) {
    auto bad = [&](const std::string& what) { throw InputError(at + what); };
    if (!(std::isfinite(s.L) && s.L > 0)) bad("L = " + fmt(s.L) + " is not a box size > 0");
    if (!(std::isfinite(s.q) && s.q > 0)) bad("q = " + fmt(s.q) + " is not a density > 0");
    if (s.sample < 0) bad("sample = " + std::to_string(s.sample) + " is negative");
    if (s.fibers < 0) bad("fibers = " + std::to_string(s.fibers) + " is negative");
    if (s.d < 0 || s.d > 3) bad("d = " + std::to_string(s.d) + " is not a clamp's degrees of freedom (0..3)");
    if (rigid != (s.d == 0 ? 1 : 0))
        bad("rigid_spanning = " + std::to_string(rigid) + " contradicts d = " + std::to_string(s.d) + " (rigid iff d = 0)");
    if (conn != 0 && conn != 1) bad("connected_spanning = " + std::to_string(conn) + " is not 0 or 1");
    if (rigid && !conn) bad("rigid_spanning = 1 with connected_spanning = 0 (a rigid cluster is connected)");
    if (!(std::isfinite(s.seconds) && s.seconds >= 0)) bad("seconds = " + fmt(s.seconds) + " is not a duration");
}

// Reads the rows of an existing CSV; an unterminated last line (an interrupted write) is skipped, any other line
// that does not parse is refused. Refuses rows that
// this run's --pl and --seed would not have made: resuming them would mix two runs. seed_of(row) is the seed the
// base seed gives for the row's L, q and sample, where it can be known: on this run's grid, or off it (an L left out
// on resume) when the row's L and q were written in under 10 significant digits, so their parsed values are exact
// (the seed hashes the exact values; a value cut to 10 digits cannot be checked).
std::vector<PercolationSample> read_rows(const std::string& path, double pl, std::uint64_t base_seed,
                                         const std::function<std::optional<std::uint64_t>(const PercolationSample&)>& seed_of,
                                         bool& ends_with_newline) {
    std::ifstream in(path);
    std::vector<PercolationSample> rows;
    std::string line;
    int lineno = 0;
    ends_with_newline = true;
    std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!all.empty()) ends_with_newline = all.back() == '\n';
    std::istringstream is(all);
    std::map<Key, int> seen;  // line of each sample
    while (std::getline(is, line)) {
        ++lineno;
        if (lineno == 1) {
            if (line != kPercolationHeader)
                throw InputError(path + ":1: not a percolation CSV (header '" + line + "')");
            continue;
        }
        PercolationSample s;
        int rigid = 0, conn = 0;
        std::uint64_t seed = 0;
        // An unterminated last line is a write cut short (a killed run), even where what is left parses (its last
        // field may be cut): its sample runs again, and the line is cut off before new rows are appended.
        if (is.peek() == std::char_traits<char>::eof() && !ends_with_newline) continue;
        if (!parse_row(line, s, seed, rigid, conn)) {
            // A damaged row elsewhere is not skipped: its sample would be run again and counted twice.
            throw InputError(path + ":" + std::to_string(lineno) + ": not a percolation row (" +
                             std::to_string(std::count(line.begin(), line.end(), ',') + 1) +
                             " fields; each must be a whole number or a decimal as fibernet writes them)");
        }
        const std::string at = path + ":" + std::to_string(lineno) + ": ";
        if (std::abs(s.pl - pl) > 1e-12) throw InputError(at + "pl = " + fmt(s.pl) + " differs from --pl " + fmt(pl));
        check_row(s, rigid, conn, at);
        s.seed = seed, s.rigid = rigid, s.connected = conn;
        const auto [it, fresh] = seen.emplace(Key{fmt(s.L), fmt(s.q), s.sample}, lineno);
        if (!fresh)
            throw InputError(at + "L = " + fmt(s.L) + ", q = " + fmt(s.q) + ", sample " + std::to_string(s.sample) +
                             " is already on line " + std::to_string(it->second) + " (a sample counts once)");
        const std::optional<std::uint64_t> expected = seed_of(s);
        if (expected && s.seed != *expected)
            throw InputError(path + ":" + std::to_string(lineno) + ": seed = " + std::to_string(s.seed) + " of L = " +
                             fmt(s.L) + ", q = " + fmt(s.q) + ", sample " + std::to_string(s.sample) +
                             " is not the seed --seed " + std::to_string(base_seed) + " gives (" +
                             std::to_string(*expected) + "): the CSV was written with another --seed");
        rows.push_back(s);
    }
    return rows;
}

nlohmann::json fit_json(const ProbitFit& f) {
    if (!f.ok) return nullptr;
    return {{"q_half", f.q_half}, {"q_half_err", f.q_half_err}, {"width", f.width}, {"width_err", f.width_err}};
}
nlohmann::json fit_json(const ScalingFit& f) {
    if (!f.ok) return nullptr;
    return {{"q_c", f.q_c}, {"q_c_err", f.q_c_err}, {"nu", f.nu},   {"nu_err", f.nu_err},
            {"A", f.A},     {"A_err", f.A_err},     {"chi2", f.chi2}, {"dof", f.dof}};
}
nlohmann::json fit_json(const WidthScalingFit& f) {
    if (!f.ok) {
        nlohmann::json j = {{"no_fit", f.reason}, {"points", f.points}};
        if (std::isfinite(f.inv_nu)) j["inv_nu"] = f.inv_nu, j["inv_nu_err"] = f.inv_nu_err;
        return j;
    }
    return {{"inv_nu", f.inv_nu}, {"inv_nu_err", f.inv_nu_err}, {"nu", f.nu}, {"nu_err", f.nu_err}, {"c", f.c},
            {"c_err", f.c_err},   {"chi2", f.chi2},             {"dof", f.dof}, {"points", f.points}};
}
// q_c with nu from the widths: the fixed-nu fit's fields plus the two parts of the q_c and A errors.
nlohmann::json width_nu_json(const ScalingFit& f) {
    nlohmann::json j = fit_json(f);
    if (!j.is_null())
        j["q_c_err_stat"] = f.q_c_err_stat, j["q_c_err_nu"] = f.q_c_err_nu, j["A_err_stat"] = f.A_err_stat,
        j["A_err_nu"] = f.A_err_nu;
    return j;
}
// The width fit without the smallest size (a check for corrections to scaling at small L) or without the largest
// (whose width, the narrowest, rests on the fewest densities inside the transition).
WidthScalingFit width_fit_without(std::vector<double> L, std::vector<double> w, std::vector<double> e, bool largest) {
    if (!L.empty()) {
        const size_t k = (largest ? std::max_element(L.begin(), L.end()) : std::min_element(L.begin(), L.end())) -
                         L.begin();
        L.erase(L.begin() + k), w.erase(w.begin() + k), e.erase(e.begin() + k);
    }
    return fit_width_scaling(L, w, e);
}
struct PercolationOpts {
    double pl = 1, q_min = 0, q_max = 0, q_step = 0;
    std::vector<double> L;
    int samples = 0, threads = 2;
    std::uint64_t seed = 1;
    std::string out, table, summary;
    bool resume = false, quiet = false;
};

struct Item {
    double L, q;
    int sample;
};

void check_opts(const PercolationOpts& o) {
    const std::string w = "command line";
    check_value(o.pl > 0 && o.pl <= 1, o.pl, w, "--pl", "must lie in (0, 1]");
    for (double L : o.L) check_value(L > 0 && L <= 2000, L, w, "--L", "must lie in (0, 2000]");
    check_value(o.q_min > 0, o.q_min, w, "--q-min", "must be > 0");
    check_value(o.q_max >= o.q_min, o.q_max, w, "--q-max", "must be >= --q-min");
    check_value(o.q_step > 0, o.q_step, w, "--q-step", "must be > 0");
    check_value((o.q_max - o.q_min) / o.q_step <= 10000, o.q_step, w, "--q-step", "gives more than 10000 densities");
    check_value(o.samples >= 1 && o.samples <= 1000000, o.samples, w, "--samples", "must lie in [1, 1e6]");
    check_value(o.threads >= 1 && o.threads <= 256, o.threads, w, "--threads", "must lie in [1, 256]");
    check_outputs({{"--out", o.out}, {"--table", o.table}, {"--summary", o.summary}, {"--out (sidecar)", o.out + ".json"},
                   {"--table (sidecar)", o.table.empty() ? "" : o.table + ".json"}});
}

int density_count(const PercolationOpts& o) {
    return static_cast<int>(std::floor((o.q_max - o.q_min) / o.q_step + 1e-9)) + 1;
}
double density_at(const PercolationOpts& o, int k) { return std::round((o.q_min + k * o.q_step) * 1e9) / 1e9; }

// Every sample of the run, L-major: a sample's index into this list is what the ranks pass around.
std::vector<Item> grid_items(const PercolationOpts& o) {
    std::vector<Item> items;
    for (double L : o.L)
        for (int k = 0; k < density_count(o); ++k)
            for (int s = 0; s < o.samples; ++s) items.push_back({L, density_at(o, k), s});
    return items;
}

// Rank 0: the rows of an existing CSV (--resume) and the samples it lacks. This run's (L, q) values by their CSV
// text: a row's seed is checked against the exact values where the 10 digits written lost some.
std::vector<PercolationSample> existing_rows(const PercolationOpts& o, bool& newline) {
    std::map<std::pair<std::string, std::string>, std::pair<double, double>> grid;
    for (double L : o.L)
        for (int k = 0; k < density_count(o); ++k) grid[{fmt(L), fmt(density_at(o, k))}] = {L, density_at(o, k)};
    auto short_text = [](double v) {  // fewer than 10 significant digits in the CSV: parsed back exactly
        int digits = 0;
        bool leading = true;
        for (char ch : fmt(v)) {
            if (ch == 'e' || ch == 'E') break;
            if (ch < '0' || ch > '9') continue;
            if (leading && ch == '0') continue;
            leading = false, ++digits;
        }
        return digits < 10;
    };
    auto seed_of = [&](const PercolationSample& r) -> std::optional<std::uint64_t> {
        auto it = grid.find({fmt(r.L), fmt(r.q)});
        if (it != grid.end()) return percolation_seed(o.seed, it->second.first, it->second.second, r.sample);
        if (short_text(r.L) && short_text(r.q)) return percolation_seed(o.seed, r.L, r.q, r.sample);
        return std::nullopt;
    };
    newline = true;
    std::ifstream probe(o.out);
    if (!probe.good()) return {};
    if (!o.resume) throw InputError("command line: --out " + o.out + " exists; add --resume to continue it");
    return read_rows(o.out, o.pl, o.seed, seed_of, newline);
}

// Rank 0's CSV: the header on a new file, then one row per finished sample as it arrives. A torn last line (a write
// cut short) is cut off first, so that no damaged row ends up between whole ones.
struct SampleCsv {
    std::ofstream csv;
    SampleCsv(const std::string& path, bool new_file, bool newline) {
        if (!newline) {
            std::ifstream in(path, std::ios::binary);
            const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
            std::error_code ec;
            std::filesystem::resize_file(path, all.rfind('\n') == std::string::npos ? 0 : all.rfind('\n') + 1, ec);
            if (ec) throw InputError("command line: --out " + path + ": cannot cut its torn last line (" + ec.message() + ")");
        }
        csv.open(path, std::ios::app);
        if (!csv) throw InputError("command line: cannot open --out " + path + " for writing");
        if (new_file) {
            std::ifstream probe(path);
            if (probe.peek() == std::ifstream::traits_type::eof()) csv << kPercolationHeader << '\n';
        }
        csv.flush();
    }
};

// Rank 0: prepares the CSV and lists the samples to run; the message (empty: go on) reaches every rank.
std::string prepare(const PercolationOpts& o, const std::vector<Item>& items, std::vector<PercolationSample>& rows,
                    std::vector<std::size_t>& todo, std::unique_ptr<SampleCsv>& csv) {
    try {
        bool newline = true;
        rows = existing_rows(o, newline);
        std::set<Key> done;
        for (const auto& r : rows) done.insert({fmt(r.L), fmt(r.q), r.sample});
        for (std::size_t i = 0; i < items.size(); ++i)
            if (!done.count({fmt(items[i].L), fmt(items[i].q), items[i].sample})) todo.push_back(i);
        if (!todo.empty()) csv = std::make_unique<SampleCsv>(o.out, rows.empty(), newline);
        return "";
    } catch (const InputError& e) {
        return e.what();
    }
}

// P(q) per L from every row (earlier runs with other q ranges included), the fits, the JSON summary.
void summarize(const PercolationOpts& opts, const std::vector<PercolationSample>& rows) {
    const PercolationOpts* o = &opts;
    // P(q) per L from every row in the CSV (earlier runs with other q ranges included).
    std::map<double, std::map<double, std::array<int, 3>>> counts;  // L -> q -> {n, rigid, connected}
    for (const auto& r : rows) {
        auto& c = counts[r.L][r.q];
        c[0] += 1, c[1] += r.rigid, c[2] += r.connected;
    }
    std::ostringstream table;
    table << "pl,L,q,samples,P_rigid,P_connected\n";
    nlohmann::json per_L = nlohmann::json::array();
    std::vector<double> Lr, yr, er, wr, wer, Lc, yc, ec, wc, wec;  // sizes with a probit fit: q_1/2, width
    for (const auto& [L, byq] : counts) {
        std::vector<double> qs;
        std::vector<int> n, hr, hc;
        for (const auto& [q, c] : byq) {
            qs.push_back(q), n.push_back(c[0]), hr.push_back(c[1]), hc.push_back(c[2]);
            table << fmt(o->pl) << ',' << fmt(L) << ',' << fmt(q) << ',' << c[0] << ',' << fmt(double(c[1]) / c[0]) << ','
                  << fmt(double(c[2]) / c[0]) << '\n';
        }
        const ProbitFit fr = fit_spanning_probability(qs, hr, n), fc = fit_spanning_probability(qs, hc, n);
        if (fr.ok)
            Lr.push_back(L), yr.push_back(fr.q_half), er.push_back(fr.q_half_err), wr.push_back(fr.width),
                wer.push_back(fr.width_err);
        if (fc.ok)
            Lc.push_back(L), yc.push_back(fc.q_half), ec.push_back(fc.q_half_err), wc.push_back(fc.width),
                wec.push_back(fc.width_err);
        long samples = 0;
        for (int k : n) samples += k;
        per_L.push_back({{"L", L}, {"samples", samples}, {"densities", qs.size()}, {"rigid", fit_json(fr)},
                         {"connected", fit_json(fc)}});
    }
    const nlohmann::json params = {{"pl", o->pl},          {"L", o->L},         {"q_min", o->q_min},
                                   {"q_max", o->q_max},    {"q_step", o->q_step}, {"samples", o->samples},
                                   {"seed", o->seed}};
    write_csv_sidecar(o->out, params,
                      {{"pl", "crosslink probability"}, {"L", "box side (fiber lengths)"}, {"q", "density N lf^2 / A"},
                       {"sample", "sample index at (L, q)"}, {"seed", "the sample's network seed (hashed)"},
                       {"fibers", "fibers in the box"}, {"d", "top clamp's degrees of freedom, bottom held (0..3)"},
                       {"rigid_spanning", "1 if d = 0"}, {"connected_spanning", "1 if the clamps are joined by pins"},
                       {"seconds", "wall time of the sample"}});
    if (!o->table.empty()) {
        write_file_atomic(o->table, table.str());
        write_csv_sidecar(o->table, params,
                          {{"pl", "crosslink probability"}, {"L", "box side (fiber lengths)"},
                           {"q", "density N lf^2 / A"}, {"samples", "samples at (L, q)"},
                           {"P_rigid", "fraction rigidly spanning"}, {"P_connected", "fraction connected spanning"}});
    }
    // nu from the probit widths, width(L) = c L^(-1/nu), then q_c with nu held there (docs/rigidity.md).
    const WidthScalingFit width_r = fit_width_scaling(Lr, wr, wer), width_c = fit_width_scaling(Lc, wc, wec);
    double cpu = 0;
    for (const auto& r : rows) cpu += r.seconds;
    emit_json({{"pl", o->pl},
               {"csv", o->out},
               {"rows", rows.size()},
               {"sample_seconds_total", cpu},
               {"per_L", per_L},
               {"scaling",
                {{"model", "q_half(L) = q_c + A L^(-1/nu)"},
                 {"rigid", fit_json(fit_finite_size_scaling(Lr, yr, er))},
                 {"connected", fit_json(fit_finite_size_scaling(Lc, yc, ec))},
                 // Known exponents: 2D rigidity percolation nu = 1.21 (Jacobs & Thorpe 1995, bond-diluted
                 // triangular lattice), 2D connectivity percolation nu = 4/3 (exact).
                 {"rigid_nu_1.21", fit_json(fit_finite_size_scaling_fixed_nu(Lr, yr, er, 1.21))},
                 {"connected_nu_4/3", fit_json(fit_finite_size_scaling_fixed_nu(Lc, yc, ec, 4.0 / 3.0))},
                 {"width_model", "width(L) = c L^(-1/nu)"},
                 {"rigid_width", fit_json(width_r)},
                 {"connected_width", fit_json(width_c)},
                 {"rigid_width_without_smallest_L", fit_json(width_fit_without(Lr, wr, wer, false))},
                 {"connected_width_without_smallest_L", fit_json(width_fit_without(Lc, wc, wec, false))},
                 {"rigid_width_without_largest_L", fit_json(width_fit_without(Lr, wr, wer, true))},
                 {"connected_width_without_largest_L", fit_json(width_fit_without(Lc, wc, wec, true))},
                 {"rigid_nu_from_width", width_nu_json(fit_finite_size_scaling_width_nu(Lr, yr, er, width_r))},
                 {"connected_nu_from_width",
                  width_nu_json(fit_finite_size_scaling_width_nu(Lc, yc, ec, width_c))}}}},
              o->summary);
}

// The samples on this process's threads and, under mpirun, on every rank (scan_comm.hpp); rank 0 writes each
// finished sample's row to the CSV at once.
void run_percolation(const PercolationOpts& o) {
    check_opts(o);
    const std::vector<Item> items = grid_items(o);
    auto comm = start_scan_comm();
    std::vector<PercolationSample> rows;
    std::vector<std::size_t> todo;
    std::unique_ptr<SampleCsv> csv;
    const std::string verdict = comm->share(comm->rank() == 0 ? prepare(o, items, rows, todo, csv) : "");
    if (!verdict.empty()) {
        end_if_not_root(comm, 2);
        throw InputError(verdict);
    }
    SampleQueue queue(std::move(todo), o.quiet ? -1.0 : 2.0, "percolation pl=" + fmt(o.pl));
    const std::size_t before = rows.size();
    bool write_failed = false;
    const DispatchOutcome out = comm->run(
        comm->rank() == 0 ? &queue : nullptr,
        [&](std::size_t i) {
            const PercolationSample s = percolation_sample(o.pl, items[i].L, items[i].q, items[i].sample, o.seed);
            SampleReport r;
            r.seconds = s.seconds, r.payload = csv_line(s);
            return r;
        },
        comm->size() > 1 ? 1 : o.threads,
        [&](std::size_t i, const SampleReport& r) {
            PercolationSample s;
            std::uint64_t seed = 0;
            int rigid = 0, conn = 0;
            std::string line = r.payload;
            if (!line.empty() && line.back() == '\n') line.pop_back();
            if (write_failed || !parse_row(line, s, seed, rigid, conn)) return;
            csv->csv << r.payload << std::flush;
            if (!csv->csv) {  // a full device: stop taking samples; reported after the pool
                write_failed = true;
                queue.stop();
                return;
            }
            s.L = items[i].L, s.q = items[i].q, s.seed = seed, s.rigid = rigid, s.connected = conn;  // exact L, q
            rows.push_back(s);
        });
    (void)out;
    comm->barrier();
    end_if_not_root(comm, 0);
    if (write_failed)
        throw OutputError("cannot append samples to --out '" + o.out + "' (" + std::to_string(rows.size() - before) +
                          " written; --resume continues)");
    summarize(o, rows);
}
}  // namespace

void register_percolation(CLI::App& app) {
    auto* cmd = app.add_subcommand("percolation", "rigidity and connectivity percolation: P(q) per L (CSV), q_1/2(L) "
                                                  "and the finite-size scaling fit q_c, nu (JSON); mpirun -n K runs "
                                                  "its samples on K ranks");
    auto o = std::make_shared<PercolationOpts>();
    cmd->add_option("--pl", o->pl, "crosslink probability")->required();
    cmd->add_option("--L", o->L, "box sizes in fiber lengths (list)")->required()->delimiter(',');
    cmd->add_option("--q-min", o->q_min, "first density")->required();
    cmd->add_option("--q-max", o->q_max, "last density")->required();
    cmd->add_option("--q-step", o->q_step, "density step")->required();
    cmd->add_option("--samples", o->samples, "networks per (L, q)")->required();
    cmd->add_option("--seed", o->seed, "base seed, an integer in [0, 2^64) (default 1)")->check(seed_check());
    cmd->add_option("--threads", o->threads, "worker threads (default 2; one per rank under mpirun)");
    cmd->add_option("--out", o->out, "CSV of samples, appended per sample")->required();
    cmd->add_flag("--resume", o->resume, "continue an existing CSV: run only the samples it lacks");
    cmd->add_option("--table", o->table, "also write P(q) per L as CSV here");
    cmd->add_option("--summary", o->summary, "write the JSON summary here instead of stdout");
    cmd->add_flag("-q,--quiet", o->quiet, "no progress lines on stderr");
    cmd->callback([o] { run_percolation(*o); });
}

}  // namespace fibernet::cli
