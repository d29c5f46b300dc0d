#include "unknown_flags.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

#include "fibernet/util/error.hpp"

namespace fibernet::cli {
namespace {

std::string lower(std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string without_dashes(const std::string& s) {
    const std::size_t p = s.find_first_not_of('-');
    return p == std::string::npos ? std::string() : s.substr(p);
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diag = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

// True when `word` occurs in `text` as a whole word (letters on neither side), case aside.
bool names_word(const std::string& text, const std::string& word) {
    const std::string t = lower(text);
    for (std::size_t p = t.find(word); p != std::string::npos; p = t.find(word, p + 1)) {
        const bool left = p == 0 || !std::isalpha(static_cast<unsigned char>(t[p - 1]));
        const std::size_t e = p + word.size();
        const bool right = e == t.size() || !std::isalpha(static_cast<unsigned char>(t[e]));
        if (left && right) return true;
    }
    return false;
}

const CLI::App* find_command(const CLI::App& app, const std::string& name) {
    for (const CLI::App* sub : app.get_subcommands({}))
        if (sub->check_name(name)) return sub;
    return nullptr;
}

bool is_flag_word(const std::string& t) {
    if (t.size() > 2 && t[0] == '-' && t[1] == '-') return true;
    return t.size() == 2 && t[0] == '-' && std::isalpha(static_cast<unsigned char>(t[1]));
}

std::string unknown_flag_message(const CLI::App& app, const CLI::App& command, const std::string& name) {
    std::string msg = "unknown flag '" + name + "' for 'fibernet " + command.get_name() + "'";
    const std::string near = nearest_flag(command, name);
    if (!near.empty()) msg += " (did you mean " + near + "?)";
    std::string others;
    for (const CLI::App* sub : app.get_subcommands({}))
        if (sub != &command && sub->get_option_no_throw(name) != nullptr)
            others += (others.empty() ? "" : ", ") + sub->get_name();
    if (!others.empty()) msg += "; " + name + " is a flag of: " + others;
    return msg + " (fibernet " + command.get_name() + " --help lists its flags)";
}

}  // namespace

std::string nearest_flag(const CLI::App& command, const std::string& unknown) {
    const std::string word = lower(without_dashes(unknown));
    if (word.empty()) return "";
    // A misspelling first: the long name within a third of the word's letters (at least one) of it.
    std::string best;
    std::size_t best_d = std::max<std::size_t>(1, word.size() / 3) + 1;
    for (const CLI::Option* o : command.get_options()) {
        for (const std::string& l : o->get_lnames()) {
            const std::size_t d = edit_distance(word, lower(l));
            if (d < best_d) best_d = d, best = "--" + l;
        }
    }
    if (!best.empty()) return best;
    // Otherwise the one flag whose description names the word ("density" -> --q, "density N lf^2 / A").
    const CLI::Option* only = nullptr;
    int hits = 0;
    for (const CLI::Option* o : command.get_options()) {
        if (o->get_lnames().empty() || !names_word(o->get_description(), word)) continue;
        only = o, ++hits;
    }
    return hits == 1 ? "--" + only->get_lnames().front() : "";
}

void check_command_line(const CLI::App& app, const std::vector<std::string>& args) {
    if (args.empty()) return;
    const CLI::App* command = find_command(app, args[0]);
    if (!command) return;
    const bool has_scene = command->get_option_no_throw("scene") != nullptr;
    const std::size_t n = args.size();
    for (std::size_t i = 1; i < n; ++i) {
        const std::string& t = args[i];
        if (t == "--") break;
        if (!is_flag_word(t)) continue;
        const std::string name = t.substr(0, t.find('='));
        const CLI::Option* o = command->get_option_no_throw(name);
        if (!o) o = app.get_option_no_throw(name);
        if (!o) throw InputError("command line: " + unknown_flag_message(app, *command, name));
        if (t.find('=') != std::string::npos) continue;
        if (o->get_items_expected_max() == 0) {
            // A flag without a value: a word after it is a positional, the scene file where the command has one.
            if (has_scene && i + 1 < n && !args[i + 1].empty() && args[i + 1][0] != '-' &&
                !std::filesystem::exists(args[i + 1]))
                throw InputError("command line: '" + args[i + 1] + "' is not a scene file (no such file); " +
                                 name + " takes no value, so the word after it was read as the scene file");
            continue;
        }
        // Its values: the next word always (it may start with '-', as in --gamma -0.1), more while they are no flags.
        ++i;
        if (o->get_items_expected_max() > 1)
            while (i + 1 < n && !is_flag_word(args[i + 1])) ++i;
    }
}

}  // namespace fibernet::cli
