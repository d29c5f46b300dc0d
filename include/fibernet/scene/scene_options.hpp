#pragma once
// Every scene option, declared once: its TOML [table].key, its command-line flag (if it has one), its help text,
// and how to read and write it on a Scene. The scene parser (parse_scene), fibernet's flags (SceneFlags), the scene
// written back as TOML (to_toml: the provenance echo and fibernet scan's sample scenes) and scan's --vary keys all
// iterate this table. Defaults are the Scene's own member initializers (shown in the help from a default Scene), and
// values are checked where the library checks them (MikadoParams::check, DiscretizationParams::check,
// Scene::check), so that a program using the library without scenes gets the same checks and messages.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fibernet/scene/scene.hpp"

namespace fibernet {

enum class OptionKind { Real, Integer, Seed, Boolean, Text, Choice };

struct SceneOption {
    std::string table, key;  // [table].key in a scene file
    std::string flag;        // command-line flag, e.g. "--L" (empty: scene files only)
    std::string doc;         // help text, without the default
    OptionKind kind = OptionKind::Real;
    // The member it sets; exactly the accessor of its kind is non-null. A Choice is text in the file that parses into
    // an enumeration (scheme, strain): set throws InputError for an unknown word, get gives the word back.
    std::function<double&(Scene&)> real;
    std::function<int&(Scene&)> integer;
    std::function<std::uint64_t&(Scene&)> seed;
    std::function<bool&(Scene&)> boolean;
    std::function<std::string&(Scene&)> text;
    std::function<void(Scene&, const std::string&)> set_choice;
    std::function<std::string(const Scene&)> get_choice;
    bool flag_sets_false = false;  // a Boolean whose flag turns it off (--open: periodic = false)
    std::string negation;          // a Boolean's second flag, which turns it off (--no-eliminate); empty: none
    bool existing_file = false;    // a Text that names a file which must exist (checked when the flag is parsed)

    std::string name() const { return table + "." + key; }
    // The value as a TOML literal (floats round-trip: toml_float).
    std::string literal(const Scene& s) const;
    // Sets the value from command-line text; InputError "<where>: <flag> = '<text>' ..." if it is not one.
    void set_from_text(Scene& s, const std::string& text, const std::string& where) const;
};

// In the order scene files list them: [network], [model], [load], [solver], [wet].
const std::vector<SceneOption>& scene_options();
// The option of [table].key, or null.
const SceneOption* find_scene_option(const std::string& table, const std::string& key);

}  // namespace fibernet
