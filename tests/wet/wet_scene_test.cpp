// The [wet] table of a scene (docs/formats.md, "Wet scenes").
#include <catch2/catch.hpp>
#include <fstream>

#include "fibernet/scene/scene.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

TEST_CASE("wet scene: values are read and bad ones named", "[wet][scene]") {
    const Scene s = parse_scene("[wet]\nbeta = 0.3\ncrossings = \"fraction\"\nfraction = 0.25\nseed = 7\n", "w.toml");
    CHECK(s.wet.beta == 0.3);
    CHECK(s.wet.crossings == "fraction");
    CHECK(s.wet.fraction == 0.25);
    CHECK(s.wet.seed == 7);
    CHECK(parse_scene("", "empty.toml").wet.crossings == "all");
    struct Bad {
        std::string toml, needle;
    };
    for (const Bad& b : {Bad{"[wet]\nbeta = -0.1\n", "[wet].beta = -0.1"}, Bad{"[wet]\nbeta = nan\n", "[wet].beta = nan"},
                         Bad{"[wet]\nfraction = 1.5\n", "[wet].fraction = 1.5"},
                         Bad{"[wet]\ncrossings = \"most\"\n", "most"}, Bad{"[wet]\nbeta = \"big\"\n", "[wet].beta"},
                         Bad{"[wet]\nwetness = 1\n", "wetness"},
                         Bad{"[wet]\nlaw = \"/nonexistent/law.txt\"\n", "/nonexistent/law.txt"}}) {
        INFO(b.toml);
        try {
            parse_scene(b.toml, "bad.toml");
            FAIL("no error");
        } catch (const InputError& e) {
            CHECK(std::string(e.what()).find(b.needle) != std::string::npos);
            CHECK(std::string(e.what()).find("bad.toml") != std::string::npos);
        }
    }
}
