// Spring strain (strain.hpp): the largest strain per kind and over the membrane, checked by hand.
#include "support.hpp"

#include "clothsim/strain.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>

using namespace clothsim;

TEST_CASE("strain: max_strain of a hand-built topology, per kind and over the membrane", "[strain]") {
    Topology t;
    t.springs = {
        {0, 1, 1.0f, SpringKind::Structural},  // 1.1 m long: +10%
        {1, 2, 2.0f, SpringKind::Shear},       // 1.5 m long: -25%
        {0, 2, 1.0f, SpringKind::Bending},     // 1.86 m long: +86%, left out of the membrane
        {2, 3, 2.0f, SpringKind::Structural},  // 1.9 m long: -5%
    };
    DVec3Array x;
    x.resize(4);
    x.set(0, {0.0, 0.0, 0.0});
    x.set(1, {1.1, 0.0, 0.0});
    x.set(2, {1.1, 1.5, 0.0});
    x.set(3, {1.1, 1.5, 1.9});
    CHECK(max_strain(t, x, SpringKind::Structural) == Approx(0.1).epsilon(1e-12));
    CHECK(max_strain(t, x, SpringKind::Shear) == Approx(-0.25).epsilon(1e-12));  // the largest may be a compression
    CHECK(max_strain(t, x, SpringKind::Bending) == Approx(std::sqrt(1.1 * 1.1 + 1.5 * 1.5) - 1.0).epsilon(1e-12));
    CHECK(max_membrane_strain(t, x) == Approx(0.1).epsilon(1e-12));

    // A cloth at rest is unstrained; a kind with no spring has no largest strain; nor has a cloth that blew up.
    Scene s;
    s.cloth.rows = 1;
    s.cloth.cols = 4;
    const MassSpring line = build_simulation(s);  // one row: structural and bending springs only
    CHECK(std::abs(max_membrane_strain(line.topology(), line.state().position)) < 1e-6);
    CHECK(std::isnan(max_strain(line.topology(), line.state().position, SpringKind::Shear)));
    x.set(3, {NAN, 0.0, 0.0});
    CHECK(std::isnan(max_membrane_strain(t, x)));
}
