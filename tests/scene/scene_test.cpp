#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "fibernet/scene/scene.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

TEST_CASE("scene: values are read and defaults kept", "[scene]") {
    const Scene s = parse_scene(
        "[network]\nL = 5\nq = 6.5\npl = 0.5\nseed = 3\n[model]\nscheme = \"even\"\nh = 0.5\na = 100\n"
        "prune = [\"dangling\"]\n[load]\nstrain = \"isotropic\"\ngamma = 0.01\n[solver]\ntol = 1e-9\n",
        "s.toml");
    CHECK(s.mikado.L == 5);
    CHECK(s.mikado.q == 6.5);
    CHECK(s.mikado.pl == 0.5);
    CHECK(s.mikado.seed == 3);
    CHECK(s.mikado.periodic);
    CHECK(s.discretization.scheme == Scheme::Even);
    CHECK(s.discretization.h == 0.5);
    CHECK(s.discretization.aspect_ratio == 100);
    CHECK(s.discretization.n_seg == 10);
    CHECK(s.prune.dangling);
    CHECK(!s.prune.nonspanning);
    CHECK(s.strain == StrainKind::Isotropic);
    CHECK(s.gamma == 0.01);
    CHECK(s.solver.tol == 1e-9);
    CHECK(s.solver.name == "newton");
    // Nonlinear elimination: on for the dry solves, off for the wet relaxation, unless a scene says otherwise.
    CHECK(s.solver.eliminate);
    CHECK_FALSE(s.wet.newton_eliminate);
    const Scene t = parse_scene("[solver]\neliminate = false\n[wet]\nnewton_eliminate = true\n", "t.toml");
    CHECK_FALSE(t.solver.eliminate);
    CHECK(t.wet.newton_eliminate);
}

TEST_CASE("scene: bad scenes name the file, key and value", "[scene][input]") {
    CHECK_THROWS_WITH(parse_scene("[network]\nq = -2\n", "s.toml"), Catch::Contains("s.toml: q (density) = -2"));
    CHECK_THROWS_WITH(parse_scene("[network]\npl = 2\n", "s.toml"), Catch::Contains("pl (crosslink probability) = 2"));
    CHECK_THROWS_WITH(parse_scene("[network]\nqq = 2\n", "s.toml"), Catch::Contains("unknown key 'qq'"));
    CHECK_THROWS_WITH(parse_scene("[netwrk]\n", "s.toml"), Catch::Contains("'netwrk'"));
    CHECK_THROWS_WITH(parse_scene("[network]\nq = \"high\"\n", "s.toml"), Catch::Contains("q has the wrong type"));
    CHECK_THROWS_WITH(parse_scene("[network]\nq = nan\n", "s.toml"), Catch::Contains("q (density) = nan"));
    CHECK_THROWS_WITH(parse_scene("[model]\nscheme = \"odd\"\n", "s.toml"), Catch::Contains("'odd'"));
    CHECK_THROWS_WITH(parse_scene("[model]\nn_seg = 0\n", "s.toml"), Catch::Contains("n_seg = 0"));
    CHECK_THROWS_WITH(parse_scene("[network\n", "s.toml"), Catch::Contains("s.toml:1"));
    CHECK_THROWS_WITH(parse_scene("[network]\nseed = -4\n", "s.toml"), Catch::Contains("[network].seed = -4 must be >= 0"));
    CHECK_THROWS_AS(load_scene("/nonexistent.toml"), InputError);
    // Integers out of range would wrap (max_iter = 2^32 + 2 ran 2 iterations).
    CHECK_THROWS_WITH(parse_scene("[solver]\nmax_iter = 4294967298\n", "s.toml"),
                      Catch::Contains("[solver].max_iter = 4294967298 is out of range"));
    // A box that flips or collapses is not a load (Scene::check, once overrides are in); shear keeps det F = 1 at any
    // gamma; isotropic gamma = -3 has det F = 4 > 0 but F = -2 I, a half turn.
    CHECK_THROWS_WITH(parse_scene("[load]\nstrain = \"uniaxial\"\ngamma = -2\n", "s.toml").check(),
                      Catch::Contains("gamma = -2 flips or collapses the box on the uniaxial path"));
    CHECK_THROWS_WITH(parse_scene("[load]\nstrain = \"isotropic\"\ngamma = -1\n", "s.toml").check(),
                      Catch::Contains("gamma = -1 flips or collapses"));
    CHECK_THROWS_WITH(parse_scene("[load]\nstrain = \"isotropic\"\ngamma = -3\n", "s.toml").check(),
                      Catch::Contains("gamma = -3 flips or collapses"));
    CHECK_NOTHROW(parse_scene("[load]\nstrain = \"shear\"\ngamma = -2\n", "s.toml").check());
    Scene over = parse_scene("[load]\nstrain = \"uniaxial\"\ngamma = -2\n", "s.toml");  // parses: values alone
    over.strain = StrainKind::Shear;                                                       // as --strain shear
    CHECK_NOTHROW(over.check());
    // A saved network brings its own box: generation keys beside it would be ignored.
    CHECK_THROWS_WITH(parse_scene("[network]\nfile = \"n.txt\"\npl = 0.2\n", "s.toml"),
                      Catch::Contains("[network].file = 'n.txt' is given with [network].pl"));
}

TEST_CASE("scene: a network file is found next to its scene and must exist", "[scene][input]") {
    const std::string dir = "/tmp/fibernet_scene_test_dir";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/net.txt") << "fibernet-network 1\nbox 10 open\nfibers 1\n0 0 0 1\ncrossings 0\n";
    std::ofstream(dir + "/ok.toml") << "[network]\nfile = \"net.txt\"\n";
    std::ofstream(dir + "/missing.toml") << "[network]\nfile = \"gone.txt\"\n";
    CHECK(load_scene(dir + "/ok.toml").network_file == dir + "/net.txt");
    CHECK_THROWS_WITH(load_scene(dir + "/missing.toml"),
                      Catch::Contains("missing.toml: [network].file = '" + dir + "/gone.txt' is not a readable file"));
}

TEST_CASE("scene: another of fibernet's files given as the scene is named for what it is", "[scene][input]") {
    // `fibernet rigidity net.txt` answered with toml++'s "expected '=', saw '1'".
    const std::string dir = "/tmp/fibernet_scene_test_dir";
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/n.net") << "fibernet-network 1\nbox 10 open\nfibers 1\n0 0 0 1\ncrossings 0\n";
    std::ofstream(dir + "/m.txt") << "fibernet-model 1\nbox 100 open\n";
    std::ofstream(dir + "/s.ckpt") << "fibernet-sweep-checkpoint 2\nparameters {}\n";
    CHECK_THROWS_WITH(load_scene(dir + "/n.net"),
                      Catch::Contains("n.net' is a network file, not a scene (TOML): give it as --network " + dir + "/n.net"));
    CHECK_THROWS_WITH(load_scene(dir + "/m.txt"), Catch::Contains("m.txt' is a model file"));
    std::ofstream(dir + "/bom.net") << "\xEF\xBB\xBF" << "fibernet-network 1\nbox 10 open\nfibers 0\ncrossings 0\n";
    CHECK_THROWS_WITH(load_scene(dir + "/bom.net"), Catch::Contains("bom.net' is a network file"));  // saved with a BOM
    CHECK_THROWS_WITH(load_scene(dir + "/s.ckpt"), Catch::Contains("s.ckpt' is a sweep checkpoint"));
    std::ofstream(dir + "/t.toml") << "# fibernet-network 1 in a comment is still a scene\n[network]\nL = 4\n";
    CHECK(load_scene(dir + "/t.toml").mikado.L == 4);
}
