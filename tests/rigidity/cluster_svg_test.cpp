// The rigid-cluster picture: the spanning cluster's red is its own (no other cluster's hue comes near it), and the
// title and legend say what is drawn.
#include <catch2/catch.hpp>
#include <regex>
#include <set>

#include "fibernet/network/clamp.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/rigidity/body_pin.hpp"
#include "fibernet/rigidity/cluster_svg.hpp"

using namespace fibernet;

namespace {
std::string picture(double pl, RigidityResult& r) {
    MikadoParams mp;
    mp.L = 6, mp.q = 12, mp.pl = pl, mp.seed = 1, mp.periodic = false;
    const ClampedNetwork cl = clamp_network(generate_mikado(mp));
    r = analyze_rigidity(body_pin_framework(cl));
    return rigid_cluster_svg(cl.net, r);
}
}  // namespace

TEST_CASE("rigid cluster SVG: the spanning cluster, a title and a legend", "[rigidity][svg]") {
    RigidityResult r;
    const std::string svg = picture(0.65, r);
    REQUIRE(r.rigid_spanning);
    CHECK(svg.find("L = 6, q = 12, pl = 0.65") != std::string::npos);
    CHECK(svg.find("d = 0 (rigid spanning)") != std::string::npos);
    CHECK(svg.find("rigid cluster holding both clamps") != std::string::npos);
    CHECK(svg.find("stroke=\"#d00000\"") != std::string::npos);
}

TEST_CASE("rigid cluster SVG: no other cluster's hue comes near the spanning red", "[rigidity][svg]") {
    RigidityResult r;
    const std::string svg = picture(0.5, r);  // sparser: several clusters of two or more fibers
    const std::regex hsl("hsl\\((\\d+),");
    std::set<int> hues;
    for (auto it = std::sregex_iterator(svg.begin(), svg.end(), hsl); it != std::sregex_iterator(); ++it)
        hues.insert(std::stoi((*it)[1]));
    CHECK(hues.size() >= 5);
    for (int h : hues) CHECK((h >= 30 && h < 330));
}
