// A scene written back as TOML (scene/scene_toml.hpp) reads back as the same scene, key for key, and a replaced key
// carries the replacement.
#include <catch2/catch.hpp>

#include "fibernet/scene/scene.hpp"
#include "fibernet/scene/scene_toml.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
void require_same(const Scene& a, const Scene& b) {
    CHECK(a.mikado.L == b.mikado.L);
    CHECK(a.mikado.q == b.mikado.q);
    CHECK(a.mikado.pl == b.mikado.pl);
    CHECK(a.mikado.seed == b.mikado.seed);
    CHECK(a.mikado.periodic == b.mikado.periodic);
    CHECK(a.network_file == b.network_file);
    CHECK(a.discretization.scheme == b.discretization.scheme);
    CHECK(a.discretization.n_seg == b.discretization.n_seg);
    CHECK(a.discretization.h == b.discretization.h);
    CHECK(a.discretization.aspect_ratio == b.discretization.aspect_ratio);
    CHECK(a.discretization.fiber_length == b.discretization.fiber_length);
    CHECK(a.discretization.trim_ends == b.discretization.trim_ends);
    CHECK(a.prune.dangling == b.prune.dangling);
    CHECK(a.prune.nonspanning == b.prune.nonspanning);
    CHECK(a.strain == b.strain);
    CHECK(a.gamma == b.gamma);
    CHECK(a.solver.name == b.solver.name);
    CHECK(a.solver.tol == b.solver.tol);
    CHECK(a.solver.max_iter == b.solver.max_iter);
    CHECK(a.wet.beta == b.wet.beta);
    CHECK(a.wet.law == b.wet.law);
    CHECK(a.wet.crossings == b.wet.crossings);
    CHECK(a.wet.fraction == b.wet.fraction);
    CHECK(a.wet.seed == b.wet.seed);
    CHECK(a.wet.free_box == b.wet.free_box);
    CHECK(a.wet.free_box_shape == b.wet.free_box_shape);
    CHECK(a.wet.free_box_tol == b.wet.free_box_tol);
    CHECK(a.wet.max_rounds == b.wet.max_rounds);
    CHECK(a.wet.round_iterations == b.wet.round_iterations);
    CHECK(a.wet.newton_ldl == b.wet.newton_ldl);
    CHECK(a.wet.local_fraction == b.wet.local_fraction);
    CHECK(a.wet.local_threshold == b.wet.local_threshold);
    CHECK(a.wet.local_hops == b.wet.local_hops);
    CHECK(a.wet.bundle_partners == b.wet.bundle_partners);
}
}  // namespace

TEST_CASE("scene_toml: defaults and every changed key read back exactly", "[scene]") {
    const Scene d;
    require_same(parse_scene(to_toml(d), "t"), d);
    Scene s;
    s.mikado = {3.7, 0.1 + 0.2, 0.37, 9223372036854775807ull, false};  // 0.30000000000000004, TOML's largest integer
    s.discretization.scheme = Scheme::Even, s.discretization.n_seg = 7, s.discretization.h = 1.0 / 3;
    s.discretization.aspect_ratio = 123.456, s.discretization.fiber_length = 12, s.discretization.trim_ends = true;
    s.prune.dangling = s.prune.nonspanning = true;
    s.strain = StrainKind::UniaxialY, s.gamma = -1e-300;
    s.solver = {"lbfgs", 3e-9, 77};
    s.wet.beta = 2.5, s.wet.crossings = "fraction", s.wet.fraction = 0.25, s.wet.seed = 9, s.wet.free_box = true;
    s.wet.free_box_shape = "full", s.wet.free_box_tol = 1e-4, s.wet.max_rounds = 5, s.wet.round_iterations = 0;
    s.wet.newton_ldl = false, s.wet.local_fraction = 0, s.wet.local_threshold = 0.5, s.wet.local_hops = 1;
    s.wet.bundle_partners = 2, s.wet.law = "a \"quoted\" \\ path.txt";
    require_same(parse_scene(to_toml(s), "t"), s);
    Scene f;  // a saved network: no generation keys
    f.network_file = "nets/n.net";
    const std::string t = to_toml(f);
    CHECK(t.find("L = ") == std::string::npos);
    CHECK(parse_scene(t, "t").network_file == "nets/n.net");
}

TEST_CASE("scene_toml: replacements, and unknown keys refused", "[scene]") {
    const Scene s = parse_scene(to_toml(Scene{}, {{"network.q", "12"}, {"model.scheme", "\"even\""}}), "t");
    CHECK(s.mikado.q == 12);
    CHECK(s.discretization.scheme == Scheme::Even);
    CHECK_THROWS_AS(to_toml(Scene{}, {{"network.density", "1"}}), InputError);
    Scene big;  // --seed takes up to 2^64 - 1, a TOML integer only up to 2^63 - 1
    big.mikado.seed = 9223372036854775808ull;
    CHECK_THROWS_WITH(to_toml(big), Catch::Contains("network.seed = 9223372036854775808 cannot be written"));
    CHECK(toml_float(10) == "10.0");
    CHECK(toml_float(0.1) == "0.1");
    CHECK(toml_float(1e300) == "1e+300");
}
