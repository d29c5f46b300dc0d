// The [wet] table of a scene (docs/formats.md, "Wet scenes").
#include <catch2/catch.hpp>
#include <fstream>

#include "fibernet/scene/scene.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

TEST_CASE("wet scene: values are read and bad ones named", "[wet][scene]") {
    const Scene s = parse_scene("[wet]\nbeta = 0.3\ncrossings = \"fraction\"\nfraction = 0.25\nseed = 7\n", "w.toml");
    CHECK(s.wet.beta == 0.3);
    CHECK(s.wet.crossings == "fraction");
    CHECK(s.wet.fraction == 0.25);
    CHECK(s.wet.seed == 7);
    CHECK(parse_scene("", "empty.toml").wet.crossings == "all");
    CHECK(!parse_scene("", "empty.toml").wet.free_box);
    CHECK(parse_scene("", "empty.toml").wet.free_box_shape == "isotropic");
    const Scene f = parse_scene("[wet]\nfree_box = true\nfree_box_shape = \"full\"\nfree_box_tol = 1e-4\n", "f.toml");
    CHECK(f.wet.free_box);
    CHECK(f.wet.free_box_shape == "full");
    CHECK(f.wet.free_box_tol == 1e-4);
    const Scene r = parse_scene("[wet]\nmax_rounds = 50\nround_iterations = 0\n", "r.toml");
    CHECK(r.wet.max_rounds == 50);
    CHECK(r.wet.round_iterations == 0);
    CHECK(parse_scene("", "empty.toml").wet.round_iterations == 10);
    CHECK(parse_scene("", "empty.toml").wet.newton_ldl);
    CHECK(!parse_scene("[wet]\nnewton_ldl = false\n", "l.toml").wet.newton_ldl);
    const Scene loc = parse_scene("[wet]\nlocal_fraction = 0\nlocal_threshold = 0.001\nlocal_hops = 5\n", "loc.toml");
    CHECK(loc.wet.local_fraction == 0);
    CHECK(loc.wet.local_threshold == 0.001);
    CHECK(loc.wet.local_hops == 5);
    CHECK(parse_scene("", "empty.toml").wet.local_fraction == ActiveSetOptions{}.local_fraction);
    CHECK(parse_scene("", "empty.toml").wet.local_threshold == ActiveSetOptions{}.local_threshold);
    CHECK(parse_scene("", "empty.toml").wet.local_hops == ActiveSetOptions{}.local_hops);
    CHECK(parse_scene("", "empty.toml").wet.bundle_partners == ActiveSetOptions{}.bundle_partners);
    CHECK(parse_scene("[wet]\nbundle_partners = 2\n", "b.toml").wet.bundle_partners == 2);
    // A fraction without crossings = fraction would be ignored: refused once overrides are in (--crossings fraction
    // may still come from the command line).
    Scene fr = parse_scene("[wet]\nfraction = 0.5\n", "fr.toml");
    CHECK_THROWS_WITH(fr.check(), Catch::Contains("fr.toml: [wet].fraction = 0.5 is used only with crossings = fraction"));
    fr.wet.crossings = "fraction";
    CHECK_NOTHROW(fr.check());
    // The same for the seed of that draw: without crossings = fraction it changes nothing.
    Scene sd = parse_scene("[wet]\nseed = 7\n", "sd.toml");
    CHECK_THROWS_WITH(sd.check(), Catch::Contains("sd.toml: [wet].seed = 7 is used only with crossings = fraction"));
    sd.wet.crossings = "fraction";
    CHECK_NOTHROW(sd.check());
    struct Bad {
        std::string toml, needle;
    };
    for (const Bad& b : {Bad{"[wet]\nbeta = -0.1\n", "[wet].beta = -0.1"}, Bad{"[wet]\nbeta = nan\n", "[wet].beta = nan"},
                         Bad{"[wet]\nfraction = 1.5\n", "[wet].fraction = 1.5"},
                         Bad{"[wet]\ncrossings = \"most\"\n", "most"}, Bad{"[wet]\nbeta = \"big\"\n", "[wet].beta"},
                         Bad{"[wet]\nwetness = 1\n", "wetness"},
                         Bad{"[wet]\nfree_box = 1\n", "[wet].free_box"},
                         Bad{"[wet]\nfree_box_shape = \"round\"\n", "[wet].free_box_shape = 'round'"},
                         Bad{"[wet]\nfree_box_tol = -1\n", "[wet].free_box_tol = -1"},
                         Bad{"[wet]\nmax_rounds = 0\n", "[wet].max_rounds = 0"},
                         Bad{"[wet]\nround_iterations = -1\n", "[wet].round_iterations = -1"},
                         Bad{"[wet]\nround_iterations = 2.5\n", "[wet].round_iterations"},
                         Bad{"[wet]\nnewton_ldl = 1\n", "[wet].newton_ldl"},
                         Bad{"[wet]\nlocal_fraction = 1.5\n", "[wet].local_fraction = 1.5"},
                         Bad{"[wet]\nlocal_fraction = nan\n", "[wet].local_fraction = nan"},
                         Bad{"[wet]\nlocal_threshold = 0\n", "[wet].local_threshold = 0"},
                         Bad{"[wet]\nlocal_hops = -1\n", "[wet].local_hops = -1"},
                         Bad{"[wet]\nbundle_partners = -1\n", "[wet].bundle_partners = -1"},

                         Bad{"[wet]\nbundle_partners = 1.5\n", "[wet].bundle_partners"},
                         Bad{"[wet]\nlaw = \"/nonexistent/law.txt\"\n", "/nonexistent/law.txt"}}) {
        INFO(b.toml);
        try {
            parse_scene(b.toml, "bad.toml").check();  // values when parsed, the law file once overrides are in
            FAIL("no error");
        } catch (const InputError& e) {
            CHECK(std::string(e.what()).find(b.needle) != std::string::npos);
            CHECK(std::string(e.what()).find("bad.toml") != std::string::npos);
        }
    }
}
