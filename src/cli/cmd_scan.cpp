// fibernet scan: an ensemble (docs/scan.md). A scene, a grid over its keys (--vary, one axis each) and a job (one
// of fibernet's commands) run per sample; every finished sample is journaled at once, so an interrupted or killed
// scan resumes (--resume) without losing one. Serial, MPI (mpirun -n K: rank 0 hands out samples as ranks come
// free) or job arrays (--shard i/N, then --merge); samples.csv is the same bit for bit however it was run.
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include "common.hpp"
#include "fibernet_version.hpp"
#include "scan_comm.hpp"
#include "scan_job.hpp"
#include "fibernet/ensemble/grid.hpp"
#include "fibernet/ensemble/journal.hpp"
#include "fibernet/ensemble/sample_table.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/scene/scene_toml.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/util/parallel.hpp"

extern "C" void openblas_set_num_threads(int);  // OpenBLAS (linked by CHOLMOD's BLAS, CMakeLists.txt)
extern "C" int openblas_get_num_threads(void);

namespace fibernet::cli {

namespace fs = std::filesystem;

namespace {
constexpr std::size_t kMaxSamples = 100000000;

// Interrupts: the first ends the scan after the samples in progress; a second ends it at once (the samples in
// progress are lost, the finished ones are in the journals either way).
volatile std::sig_atomic_t g_interrupts = 0;
extern "C" void on_scan_signal(int) {
    if (++g_interrupts >= 2) {
        const char m[] = "scan: interrupted again; stopping now (finished samples are kept; --resume continues)\n";
        (void)!::write(2, m, sizeof m - 1);
        _exit(130);
    }
}

struct Options {
    std::vector<std::string> vary, merge, points;
    std::string job, job_args, out, shard;
    bool resume = false, quiet = false, sample_files = false;
    long long print_scene = -1;
    bool print_scene_given = false;
};

struct Shard {
    std::size_t i = 0, n = 1;
    std::string text() const { return std::to_string(i) + "/" + std::to_string(n); }
};

Shard parse_shard(const std::string& spec) {
    if (spec.empty()) return {};
    std::string s = spec;
    if (spec == "slurm") {  // a Slurm job array: one shard per array task
        const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
        const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
        const char* lo = std::getenv("SLURM_ARRAY_TASK_MIN");
        if (!id || !count)
            throw InputError("command line: --shard slurm needs SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT (run it "
                             "in a Slurm job array, sbatch --array=0-N)");
        s = std::to_string(std::atoll(id) - (lo ? std::atoll(lo) : 0)) + "/" + count;
    }
    const auto slash = s.find('/');
    Shard sh;
    try {
        std::size_t a = 0, b = 0;
        if (slash == std::string::npos) throw std::invalid_argument("");
        sh.i = std::stoull(s.substr(0, slash), &a);
        sh.n = std::stoull(s.substr(slash + 1), &b);
        if (a != slash || b != s.size() - slash - 1 || s[0] == '-' || s[slash + 1] == '-') throw std::invalid_argument("");
    } catch (const std::exception&) {
        throw InputError("command line: --shard " + spec + " is not i/N (e.g. 0/4) or slurm");
    }
    if (sh.n < 1 || sh.i >= sh.n) throw InputError("command line: --shard " + s + ": need 0 <= i < N");
    return sh;
}

std::vector<std::string> split_args(const std::string& s) {
    std::istringstream is(s);
    std::vector<std::string> v;
    for (std::string a; is >> a;) v.push_back(a);
    return v;
}

// What determines the samples: a resumed scan, a shard or a merged directory must have the same.
struct Manifest {
    std::string job, scene;  // scene: the base scene as TOML (scene_toml.hpp)
    std::vector<std::string> job_args;
    Grid grid;
    bool sample_files = false;

    nlohmann::json determining() const {
        nlohmann::json axes = nlohmann::json::array();
        for (const auto& a : grid.axes)
            axes.push_back({{"name", a.name}, {"key", a.key}, {"values", a.values}, {"labels", a.labels},
                            {"group", a.group}});
        return {{"job", job}, {"job_args", job_args}, {"axes", axes}, {"scene", scene}, {"sample_files", sample_files},
                {"samples", grid.size()}};
    }
    static Manifest from(const nlohmann::json& j, const std::string& where) {
        Manifest m;
        try {
            m.job = j.at("job").get<std::string>(), m.scene = j.at("scene").get<std::string>();
            m.job_args = j.at("job_args").get<std::vector<std::string>>();
            m.sample_files = j.at("sample_files").get<bool>();
            for (const auto& a : j.at("axes"))
                m.grid.axes.push_back({a.at("name").get<std::string>(), a.at("key").get<std::string>(),
                                       a.at("values").get<std::vector<std::string>>(),
                                       a.at("labels").get<std::vector<std::string>>(), a.value("group", -1), where});
        } catch (const nlohmann::json::exception& e) {
            throw InputError(where + ": not a scan manifest (" + e.what() + ")");
        }
        for (const auto& a : m.grid.axes)
            if (a.values.empty() || a.values.size() != a.labels.size())
                throw InputError(where + ": axis " + a.name + " has no values or a label per value missing");
        return m;
    }
};

std::string describe(const Grid& g, std::size_t index) {
    std::string s = "sample " + std::to_string(index);
    const auto c = g.coordinates(index);
    for (std::size_t k = 0; k < g.axes.size(); ++k) s += (k ? ", " : " (") + g.axes[k].name + " = " + g.axes[k].labels[c[k]];
    return s + (g.axes.empty() ? "" : ")");
}

std::string sample_scene(const Manifest& m, const Scene& base, std::size_t index) {
    return to_toml(base, m.grid.replacements(index));
}

// Every sample's scene, read back and checked as its command will check it: bad values stop the scan before any work.
void check_samples(const Manifest& m, const Scene& base) {
    std::string sources;  // where the values came from: --vary specs and points files
    for (const auto& a : m.grid.axes)
        if (!a.source.empty() && sources.find(a.source) == std::string::npos) sources += (sources.empty() ? "" : ", ") + a.source;
    for (std::size_t i = 0; i < m.grid.size(); ++i) {
        const std::string who = describe(m.grid, i) + (sources.empty() ? "" : " of " + sources);
        Scene s = parse_scene(sample_scene(m, base, i), who);
        s.check();
        if (!s.network_file.empty() && !fs::is_regular_file(s.network_file))
            throw InputError(who + ": [network].file = '" + s.network_file + "' is not a readable file");
    }
}

nlohmann::json read_json_file(const std::string& path) {
    std::ifstream is(path);
    if (!is) throw InputError("'" + path + "' cannot be opened");
    std::stringstream ss;
    ss << is.rdbuf();
    nlohmann::json j = nlohmann::json::parse(ss.str(), nullptr, false);
    if (!j.is_object()) throw InputError("'" + path + "' is not a JSON object (a scan's scan.json)");
    return j;
}

std::string host_name() {
    char b[256] = {};
    gethostname(b, sizeof b - 1);
    return b;
}

std::string unique_tag(int rank) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::system_clock::now().time_since_epoch()).count();
    return host_name() + "-" + std::to_string(getpid()) + "-" + std::to_string(ns) + "-r" + std::to_string(rank);
}

std::string command_line_text(const std::vector<std::string>& argv) {
    std::string s = "fibernet";
    for (const auto& a : argv) s += " " + a;
    return s;
}

// The directory of a scan: scan.json, journal/, work/, samples/ (sample files), and the tables.
struct ScanDir {
    std::string root;
    std::string manifest() const { return root + "/scan.json"; }
    std::string journal() const { return root + "/journal"; }
    std::string work() const { return root + "/work"; }
    std::string samples() const { return root + "/samples"; }
};

void make_dirs(const ScanDir& d, bool sample_files) {
    std::error_code ec;
    for (const auto& p : {d.root, d.journal(), d.work()}) {
        fs::create_directories(p, ec);
        if (ec) throw InputError("command line: -o " + d.root + ": cannot create '" + p + "' (" + ec.message() + ")");
    }
    if (sample_files) fs::create_directories(d.samples(), ec);
}

// The manifest of DIR, if any, must be this scan's; a new one is written (atomically: shards may start together).
void claim_dir(const ScanDir& d, const Manifest& m, bool resume, bool shard, const std::string& cmdline) {
    const nlohmann::json want = m.determining();
    if (fs::exists(d.manifest())) {
        const nlohmann::json have = read_json_file(d.manifest());
        const nlohmann::json theirs = Manifest::from(have, d.manifest()).determining();
        if (theirs != want) {
            std::string diff;
            for (const auto& [k, v] : want.items())
                if (theirs.value(k, nlohmann::json()) != v) diff += (diff.empty() ? "" : ", ") + k;
            throw InputError("command line: -o " + d.root + " holds another scan (its " + diff +
                             " differ); give another directory");
        }
        if (!resume && !shard)
            throw InputError("command line: -o " + d.root + " holds this scan already; add --resume to run the samples "
                             "it lacks");
        make_dirs(d, m.sample_files || m.job == "sweep");  // work/ went at the end of the last run
        return;
    }
    make_dirs(d, m.sample_files || m.job == "sweep");
    nlohmann::json j = want;
    j["format"] = "fibernet-scan 1";
    j["fibernet"] = {{"version", FIBERNET_VERSION}, {"commit", FIBERNET_GIT_COMMIT}};
    j["command"] = cmdline;
    write_file_atomic(d.manifest(), json_text(j, 2) + "\n");
}

// The records in index order, and the tables, from every journal in the directory.
struct Tables {
    std::size_t finished = 0, failed = 0, duplicates = 0, torn = 0;
    double sample_seconds = 0;
};

// Under a lock on DIR/.lock: shards of one directory that end together must not rename an older table over a newer.
class DirLock {
public:
    explicit DirLock(const ScanDir& d) : fd_(::open((d.root + "/.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644)) {
        if (fd_ < 0) throw OutputError("cannot open the lock '" + d.root + "/.lock' (" + std::strerror(errno) + ")");
        while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
        }
    }
    ~DirLock() { ::close(fd_); }  // closing releases the lock
    DirLock(const DirLock&) = delete;
    DirLock& operator=(const DirLock&) = delete;

private:
    int fd_;
};

Tables write_tables(const ScanDir& d, const Manifest& m) {
    const DirLock lock(d);
    const JournalContents jc = read_journals(d.journal());
    std::vector<const nlohmann::json*> recs;
    Tables t;
    t.duplicates = jc.duplicates, t.torn = jc.torn;
    std::string jsonl;
    for (const auto& [index, r] : jc.records) {
        if (index >= m.grid.size())
            throw InputError(d.journal() + ": a record of sample " + std::to_string(index) + ", past the grid's " +
                             std::to_string(m.grid.size()) + " samples");
        recs.push_back(&r);
        jsonl += r.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
        if (r.value("exit_code", -1) != 0) ++t.failed;
        t.sample_seconds += r.value("seconds", 0.0);
    }
    t.finished = recs.size();
    write_file_atomic(d.root + "/samples.csv", samples_csv(m.grid, recs));
    write_file_atomic(d.root + "/samples.jsonl", jsonl);
    write_file_atomic(d.root + "/summary.csv", summary_csv(m.grid, recs));
    return t;
}

// Runs one sample on this rank: its scene into the rank's work file, the job, the record into the journal.
class SampleWorker {
public:
    SampleWorker(const ScanDir& d, const Manifest& m, const Scene& base, int rank)
        : dir_(d), m_(m), base_(base), rank_(rank), tag_(unique_tag(rank)), scene_file_(d.work() + "/" + tag_ + ".toml") {}
    ~SampleWorker() {
        std::error_code ec;
        fs::remove(scene_file_, ec);
    }

    SampleReport operator()(std::size_t index) {
        SampleReport r;
        const auto t0 = std::chrono::steady_clock::now();
        try {
            if (!journal_) journal_ = std::make_unique<JournalWriter>(dir_.journal(), tag_);
            remove_stale_files(index);
            write_file_atomic(scene_file_, sample_scene(m_, base_, index));
            const JobOutcome o = run_job(m_.job, scene_file_, args(index));
            r.seconds = seconds_since(t0);
            if (o.exit_code == 130 || (g_interrupts > 0 && o.exit_code != 0)) {  // the job itself was interrupted
                r.interrupted = true;
                return r;
            }
            r.ok = o.exit_code == 0;
            journal_->append(record(index, o, r.seconds));
        } catch (const InputError& e) {
            r.input_error = describe(m_.grid, index) + ": " + e.what();
        } catch (const OutputError& e) {
            r.output_error = e.what();
        }
        return r;
    }

private:
    // A sample without a journal record runs from the start: what an interrupted or killed run of it left (a sweep's
    // CSV and unfinished checkpoint, which sweep would refuse without --resume) goes first.
    void remove_stale_files(std::size_t index) const {
        const std::string stem = dir_.samples() + "/sample-" + std::to_string(index);
        std::error_code ec;
        for (const char* ext : {".csv", ".csv.ckpt", ".model", ".svg"}) fs::remove(stem + ext, ec);
    }

    // Paths inside the scan's directory, relative to it ("samples/sample-3.csv"): the rows must not depend on where
    // the directory was when the sample ran (shards merged from elsewhere).
    void relative_paths(nlohmann::json& j) const {
        const std::string prefix = dir_.root + "/";
        if (j.is_string()) {
            const std::string& v = j.get_ref<const std::string&>();
            if (v.rfind(prefix, 0) == 0) j = v.substr(prefix.size());
        } else if (j.is_structured()) {
            for (auto& el : j) relative_paths(el);
        }
    }

    std::vector<std::string> args(std::size_t index) const {
        std::vector<std::string> a = m_.job_args;
        const std::string stem = dir_.samples() + "/sample-" + std::to_string(index);
        if (m_.job == "sweep") a.insert(a.end(), {"-o", stem + ".csv"});
        if (m_.sample_files) {
            if (m_.job == "relax") a.insert(a.end(), {"-o", stem + ".model"});
            if (m_.job == "rigidity") a.insert(a.end(), {"--svg", stem + ".svg"});
            if (m_.job == "wet") a.insert(a.end(), {"-o", stem});
        }
        return a;
    }

    nlohmann::json record(std::size_t index, const JobOutcome& o, double seconds) const {
        nlohmann::json params = nlohmann::json::object();
        const auto c = m_.grid.coordinates(index);
        for (std::size_t k = 0; k < m_.grid.axes.size(); ++k) params[m_.grid.axes[k].name] = m_.grid.axes[k].labels[c[k]];
        std::string status = o.exit_code == 0 ? "ok" : o.exit_code == 3 ? "internal_error" : "failed";
        if (o.result.is_object() && o.result.contains("status") && o.result["status"].is_string())
            status = o.result["status"].get<std::string>();
        nlohmann::json result = o.result;
        if (result.is_object() && result.contains("scene")) result["scene"] = describe(m_.grid, index);  // not the work file
        relative_paths(result);
        nlohmann::json j = {{"index", index}, {"params", params}, {"status", status}, {"exit_code", o.exit_code},
                            {"result", result}, {"seconds", seconds}, {"rank", rank_}, {"host", host_name()}};
        if (!o.error.empty()) j["error"] = o.error;
        return j;
    }

    const ScanDir& dir_;
    const Manifest& m_;
    const Scene& base_;
    int rank_;
    std::string tag_, scene_file_;
    std::unique_ptr<JournalWriter> journal_;
};

// Journals and sample files of other directories of the same scan (shards run apart, checked by merge_scan) copied
// into this one; what is there already is kept.
void merge_from(const ScanDir& d, const std::vector<std::string>& sources) {
    for (const auto& src : sources) {
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(ScanDir{src}.journal(), ec)) {
            if (e.path().extension() != ".jsonl") continue;
            const fs::path to = fs::path(d.journal()) / e.path().filename();
            if (fs::exists(to) && fs::file_size(to) == fs::file_size(e.path())) continue;  // merged before
            fs::copy_file(e.path(), to, fs::copy_options::overwrite_existing, ec);
            if (ec) throw OutputError("cannot copy '" + e.path().string() + "' to '" + to.string() + "' (" + ec.message() + ")");
        }
        if (ec) throw InputError("command line: --merge " + src + ": cannot read its journal (" + ec.message() + ")");
        const fs::path samples = ScanDir{src}.samples();
        if (fs::is_directory(samples, ec)) {
            fs::create_directories(d.samples(), ec);
            fs::copy(samples, d.samples(), fs::copy_options::recursive | fs::copy_options::skip_existing, ec);
            if (ec) throw OutputError("cannot copy '" + samples.string() + "' to '" + d.samples() + "' (" + ec.message() + ")");
        }
    }
}

// Element loops and OpenBLAS on one thread per rank unless asked otherwise: ranks are the parallelism (results do
// not depend on thread counts, util/parallel.hpp).
// Put back when the scan ends: a process that runs more than the scan (the Python package) keeps its threads.
struct OneThreadPerSample {
    int blas = openblas_get_num_threads();
    OneThreadPerSample() {
        if (!std::getenv("FIBERNET_THREADS")) set_thread_count(1);
        if (!std::getenv("OPENBLAS_NUM_THREADS") && !std::getenv("OMP_NUM_THREADS")) openblas_set_num_threads(1);
    }
    ~OneThreadPerSample() {
        if (!std::getenv("FIBERNET_THREADS")) set_thread_count(0);
        openblas_set_num_threads(blas);
    }
};

// The base scene as the manifest keeps it: its files by absolute path, so the scan runs from any directory.
Scene base_scene(const SceneFlags& flags) {
    Scene s = flags.resolve(false);
    std::error_code ec;
    if (!s.network_file.empty()) s.network_file = fs::absolute(s.network_file, ec).lexically_normal().string();
    if (!s.wet.law.empty()) s.wet.law = fs::absolute(s.wet.law, ec).lexically_normal().string();
    return s;
}

// The values of a varied network file or law table by absolute path (relative ones taken from the working
// directory, as on the command line): each sample's scene is read from DIR/work/.
void absolute_paths(GridAxis& a) {
    if (a.key != "network.file" && a.key != "wet.law") return;
    for (std::size_t v = 0; v < a.values.size(); ++v) {
        std::error_code ec;
        a.labels[v] = fs::absolute(a.labels[v], ec).lexically_normal().string();
        std::string q = "\"";
        for (char c : a.labels[v]) q += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
        a.values[v] = q + "\"";
    }
}

Manifest manifest_of(const SceneFlags& flags, const Options& o, Scene& base) {
    if (o.job.empty()) throw InputError("command line: --job is required (modulus, relax, rigidity, sweep or wet)");
    Manifest m;
    m.job = o.job;
    m.job_args = split_args(o.job_args);
    check_job_args(m.job, m.job_args);
    for (std::size_t k = 0; k < o.points.size(); ++k)  // the lists of points first, then the --vary axes
        for (auto& a : parse_points(file_bytes(o.points[k], "--points file"), o.points[k], static_cast<int>(k)))
            m.grid.axes.push_back(std::move(a));
    for (const auto& v : o.vary) m.grid.axes.push_back(parse_axis(v, "command line"));
    check_grid(m.grid, kMaxSamples, "command line");
    for (auto& a : m.grid.axes) absolute_paths(a);
    for (const auto& a : m.grid.axes)  // wet's --betas replaces the scene's beta: a varied beta would be ignored
        for (const auto& arg : m.job_args)
            if (a.key == "wet.beta" && arg.rfind("--betas", 0) == 0)
                throw InputError("command line: --job-args " + arg + " gives each sample its own list of betas, which "
                                 "would override --vary " + a.name + ": give one or the other");
    base = base_scene(flags);
    m.scene = to_toml(base);
    m.sample_files = o.sample_files;
    return m;
}

nlohmann::json tables_json(const ScanDir& d, const Manifest& m, const Tables& t) {
    return {{"out_dir", d.root},
            {"job", m.job},
            {"samples", m.grid.size()},
            {"finished", t.finished},
            {"failed", t.failed},
            {"missing", m.grid.size() - t.finished},
            {"complete", t.finished == m.grid.size()},
            {"duplicate_records", t.duplicates},
            {"torn_records", t.torn},
            {"sample_seconds_total", t.sample_seconds},
            {"files",
             {{"samples", d.root + "/samples.csv"}, {"records", d.root + "/samples.jsonl"},
              {"summary", d.root + "/summary.csv"}, {"manifest", d.manifest()}}}};
}

// The directory's own scan: --print-scene and --merge read it from there.
Manifest stored_manifest(const ScanDir& d, Scene& base) {
    const Manifest m = Manifest::from(read_json_file(d.manifest()), d.manifest());
    base = parse_scene(m.scene, d.manifest() + ": scene");
    return m;
}

int print_scene(const ScanDir& d, long long n) {
    Scene base;
    const Manifest m = stored_manifest(d, base);
    if (n < 0 || static_cast<std::size_t>(n) >= m.grid.size())
        throw InputError("command line: --print-scene " + std::to_string(n) + " is not a sample (0 to " +
                         std::to_string(m.grid.size() - 1) + ")");
    std::cout << "# " << describe(m.grid, static_cast<std::size_t>(n)) << " of " << d.manifest() << "; run it as: fibernet "
              << m.job << " <this file>" << (m.job_args.empty() ? "" : " " + command_line_text(m.job_args).substr(9)) << "\n"
              << sample_scene(m, base, static_cast<std::size_t>(n));
    return 0;
}

int merge_scan(const ScanDir& d, const std::vector<std::string>& sources) {
    // Every source checked before anything is written: the first one's scan, and the others must hold it too.
    const nlohmann::json first = read_json_file(ScanDir{sources.front()}.manifest());
    const Manifest m0 = Manifest::from(first, ScanDir{sources.front()}.manifest());
    for (const auto& src : sources)
        if (Manifest::from(read_json_file(ScanDir{src}.manifest()), ScanDir{src}.manifest()).determining() != m0.determining())
            throw InputError("command line: --merge " + src + " holds another scan than " + sources.front());
    if (fs::exists(d.manifest())) {
        if (Manifest::from(read_json_file(d.manifest()), d.manifest()).determining() != m0.determining())
            throw InputError("command line: -o " + d.root + " holds another scan than the --merge sources");
    } else {  // a new directory: the sources' scan
        make_dirs(d, m0.sample_files || m0.job == "sweep");
        write_file_atomic(d.manifest(), json_text(first, 2) + "\n");
    }
    Scene base;
    const Manifest m = stored_manifest(d, base);
    merge_from(d, sources);
    const Tables t = write_tables(d, m);
    emit_json(tables_json(d, m, t));
    return t.failed > 0 ? 1 : 0;
}

// Rank 0 gets the directory ready and lists this run's samples; its message (empty: go on) reaches every rank.
std::string prepare(const ScanDir& d, const Manifest& m, const Scene& base, const Options& o, const Shard& sh,
                    const std::string& cmdline, std::vector<std::size_t>& todo) {
    try {
        check_samples(m, base);
        claim_dir(d, m, o.resume, !o.shard.empty(), cmdline);
        const JournalContents done = read_journals(d.journal());
        for (std::size_t i = sh.i; i < m.grid.size(); i += sh.n) {
            if (!done.records.count(i)) todo.push_back(i);
            if (m.grid.size() - i <= sh.n) break;  // i + N would pass the grid (or wrap round)
        }
        if (!o.quiet)
            std::cerr << "scan: " << m.grid.size() << " samples of " << m.job << (sh.n > 1 ? ", shard " + sh.text() : "")
                      << ", " << todo.size() << " to run, " << (done.records.size()) << " journaled before\n";
        return "";
    } catch (const InputError& e) {
        return std::string("E2") + e.what();
    } catch (const OutputError& e) {
        return std::string("E4") + e.what();
    }
}

int run_scan(const SceneFlags& flags, const Options& o, const std::vector<std::string>& argv) {
    const ScanDir d{o.out};
    const Shard sh = parse_shard(o.shard);
    Scene base;
    const Manifest m = manifest_of(flags, o, base);
    auto comm = start_scan_comm();
    std::vector<std::size_t> todo;
    const std::string verdict = comm->share(comm->rank() == 0 ? prepare(d, m, base, o, sh, command_line_text(argv), todo) : "");
    if (!verdict.empty()) {  // ranks > 0 end quietly: rank 0 reports
        end_if_not_root(comm, verdict[1] == '4' ? 4 : 2);
        if (verdict[1] == '4') throw OutputError(verdict.substr(2));
        throw InputError(verdict.substr(2));
    }
    const OneThreadPerSample threads;
    g_interrupts = 0;
    const SignalScope signals(on_scan_signal);
    SampleQueue queue(std::move(todo), o.quiet ? -1.0 : 2.0);
    const auto t0 = std::chrono::steady_clock::now();
    DispatchOutcome out;
    {
        SampleWorker worker(d, m, base, comm->rank());
        out = comm->run(comm->rank() == 0 ? &queue : nullptr, [&](std::size_t i) {
            if (g_interrupts > 0) return SampleReport{false, 0, true, "", "", ""};
            return worker(i);
        });
    }
    const double wall = seconds_since(t0);
    comm->barrier();  // every rank's journal is complete
    end_if_not_root(comm, 0);
    if (!out.input_error.empty())
        throw InputError(out.input_error + " (the scan stopped; the samples finished before it are kept in " + d.root + ")");
    if (!out.output_error.empty()) throw OutputError(out.output_error);
    const Tables t = write_tables(d, m);
    std::error_code ec;
    fs::remove(d.work(), ec);  // empty once every rank's work file is gone (another shard may still use it)
    nlohmann::json j = tables_json(d, m, t);
    const double busy = queue.busy_seconds();
    j["run"] = {{"transport", comm->kind()},
                {"ranks", comm->size()},
                {"shard", sh.text()},
                {"samples_run", queue.done()},
                {"failed", queue.failed()},
                {"interrupted", out.interrupted || g_interrupts > 0},
                {"wall_seconds", wall},
                {"sample_seconds", busy},
                {"fraction_not_in_samples", wall > 0 && queue.done() > 0 ? 1 - busy / (wall * comm->size()) : 0.0}};
    j["command"] = command_line_text(argv);
    emit_json(j);
    if (out.interrupted || g_interrupts > 0) {
        std::cerr << "scan: interrupted; " << t.finished << " of " << m.grid.size()
                  << " samples are journaled: the same command with --resume runs the rest\n";
        return 130;
    }
    return t.failed > 0 ? 1 : 0;
}
}  // namespace

int run_scan_command(const SceneFlags& flags, const Options& o, const std::vector<std::string>& argv) {
    const ScanDir d{o.out};
    if (o.print_scene_given) return print_scene(d, o.print_scene);
    if (!o.merge.empty()) {
        if (!o.vary.empty() || !o.points.empty() || !o.job.empty() || o.resume)
            throw InputError("command line: --merge takes only -o and the source directories (their scan is in "
                             "their scan.json)");
        return merge_scan(d, o.merge);
    }
    return run_scan(flags, o, argv);
}

void register_scan(CLI::App& app) {
    auto* cmd = app.add_subcommand("scan", "an ensemble: a job per sample of a grid over scene keys; MPI, shards, "
                                           "resume; samples.csv, summary.csv (docs/scan.md)");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, true);
    auto o = std::make_shared<Options>();
    cmd->add_option("--vary", o->vary, "an axis: key=v1,v2,... | key=first:last | key=first:last:step (repeatable; "
                                       "key: L, q, pl, seed, a, h, scheme, gamma, beta, ... or table.key)");
    cmd->add_option("--points", o->points, "a list of points: a CSV file, a header of keys (e.g. L,q), a row per "
                                           "point; its columns vary together (repeatable; before the --vary axes)");
    cmd->add_option("--job", o->job, "the command run per sample: modulus | relax | rigidity | sweep | wet");
    cmd->add_option("--job-args", o->job_args, "the job's own flags, e.g. \"--start linear\" (space-separated)");
    cmd->add_option("-o,--out-dir", o->out, "the scan's directory (scan.json, journal/, samples.csv, summary.csv)")
        ->required();
    cmd->add_flag("--resume", o->resume, "run the samples the directory lacks");
    cmd->add_option("--shard", o->shard, "run only samples with index % N == i: i/N, or slurm (the array task)");
    cmd->add_option("--merge", o->merge, "copy the journals of these scan directories (shards) in; write the tables");
    cmd->add_flag("--sample-files", o->sample_files, "keep each sample's files in samples/ (relax model, svg, wet dir)");
    auto* ps = cmd->add_option("--print-scene", o->print_scene, "print sample N's scene (TOML) of the scan in -o and stop");
    cmd->add_flag("-q,--quiet", o->quiet, "no progress lines on stderr");
    cmd->callback([flags, o, ps] {
        o->print_scene_given = ps->count() > 0;
        exit_code() = run_scan_command(*flags, *o, command_argv());
    });
}

}  // namespace fibernet::cli
