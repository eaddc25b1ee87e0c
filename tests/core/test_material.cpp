// The material form: a fabric in physical units is the same cloth at every grid resolution.
#include "clothsim/material.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"
#include "support.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstdio>

using namespace clothsim;

namespace {

// A strip `length` x `width` lying flat along x in the horizontal plane, clamped at x = 0 by its first two
// columns of particles, settled under gravity; its tip's mean drop (m).
// The clamp line lies `clamp_back` spacings behind column 1: halfway between the two pinned columns (0.5) is
// where the discrete clamp holds the strip (docs/MATERIAL.md: second-order convergence there, first order at
// column 0 or 1). `springs` puts the bends' k on skip-one springs instead (the per-spring form's model).
double cantilever_drop(int along, double length, double width, double bending, double clamp_back, bool springs) {
    Scene s;
    const double h = length / (along - 1 - clamp_back);
    s.cloth.cols = along;
    s.cloth.rows = static_cast<int>(std::lround(width / h)) + 1;
    s.cloth.size = {static_cast<float>(h * (along - 1)), static_cast<float>(width)};
    s.cloth.origin = {static_cast<float>(-clamp_back * h), 1.0f, 0.0f};
    s.cloth.u_axis = {1.0f, 0.0f, 0.0f};
    s.cloth.v_axis = {0.0f, 0.0f, 1.0f};
    s.pins.preset = PinPreset::None;
    for (int r = 0; r < s.cloth.rows; ++r) s.pins.particles.push_back({r, 0}), s.pins.particles.push_back({r, 1});
    test::collider(s.settings.colliders, "ground").enabled = false;
    // Mass-proportional damping at critical for the first mode, w1 = 3.516 sqrt(B / (density L^4)) (9 rad/s at
    // B = 1e-4 N m, 91 at 1e-2), settles the strip to e^-20 in 20 / w1; it does not change the static shape.
    // Skip-one springs are far floppier than bends at small curvature: they settle from a slower, larger
    // swing, given 2 s at a damping of 18/s (critical for the 1e-4 N m strip).
    const double w1 = springs ? 9.0 : 3.516 * std::sqrt(bending / (0.15 * std::pow(length, 4)));
    s.settings.springs.damping = static_cast<float>(2.0 * w1);
    s.settings.solver.sleep_speed = 0.0f;
    s.material.enabled = true;
    s.material.density = 0.15f;
    s.material.stretch = glm::vec2(1000.0f);
    s.material.shear = 100.0f;
    s.material.bending = glm::vec2(static_cast<float>(bending));
    if (springs) {
        // The per-spring form with the bends' k on skip-one springs.
        derive_springs(s);
        s.material.enabled = false;
    }
    MassSpring sim = build_simulation(s);
    const StabilityLimit limit = stability_limit(sim);
    sim.set_substeps(auto_substeps(limit, s.settings.integration.dt, 0.8f, 1));
    sim.run_steps(static_cast<long long>(std::ceil((springs ? 2.0 : 20.0 / w1) / s.settings.integration.dt)));
    double drop = 0.0;
    for (int r = 0; r < s.cloth.rows; ++r) drop += 1.0 - sim.state().position.y[static_cast<std::size_t>(r) * along + along - 1];
    return drop / s.cloth.rows;
}

}  // namespace

TEST_CASE("material: a clamped strip's tip drop matches the heavy elastica within 3% at 33 particles and 1.5% at "
          "65, converging", "[material][convergence]") {
    // The strip: 0.1 m x 0.025 m, density 0.15 kg/m^2, B = 1e-4 N m, stretch 1000 N/m (strain 1.5e-4 at
    // this load: inextensible).
    const double q = 0.15 * 9.81;
    const double exact = test::elastica_tip_drop(0.1, 1e-4, q);
    // Large deflection: the linear formula q L^4 / 8B would say 0.184 m, more than the strip's length.
    REQUIRE(exact == Approx(0.0783).epsilon(0.01));
    const double coarse = cantilever_drop(33, 0.1, 0.025, 1e-4, 0.5, false);
    const double fine = cantilever_drop(65, 0.1, 0.025, 1e-4, 0.5, false);
    INFO("elastica " << exact << " m; 33 particles " << coarse << ", 65 particles " << fine);
    CHECK(std::abs(coarse / exact - 1.0) < 0.03);
    CHECK(std::abs(fine / exact - 1.0) < 0.015);
    CHECK(std::abs(fine - exact) < std::abs(coarse - exact));
}

TEST_CASE("material: a stiff clamped strip's tip drop matches the small-deflection w L^4 / 8B", "[material][convergence]") {
    const double q = 0.15 * 9.81, b = 1e-2;
    const double linear = q * std::pow(0.1, 4) / (8.0 * b);
    REQUIRE(test::elastica_tip_drop(0.1, b, q) == Approx(linear).epsilon(1e-3));  // the elastica agrees here
    const double coarse = cantilever_drop(33, 0.1, 0.025, b, 0.5, false);
    const double fine = cantilever_drop(65, 0.1, 0.025, b, 0.5, false);
    INFO("w L^4 / 8B = " << linear << " m; 33 particles " << coarse << ", 65 particles " << fine);
    CHECK(std::abs(coarse / linear - 1.0) < 0.03);
    CHECK(std::abs(fine / linear - 1.0) < 0.015);
    CHECK(std::abs(fine - linear) < std::abs(coarse - linear));
}

// The study behind the choice of bends over skip-one springs (docs/MATERIAL.md): run with
//   build/release/tests/test_core "material study*"
TEST_CASE("material study: bends and skip-one springs against the elastica", "[material][.study]") {
    const double q = 0.15 * 9.81;
    for (double b : {1e-4, 1e-2}) {
        const double exact = test::elastica_tip_drop(0.1, b, q);
        std::printf("B = %g N m: elastica tip drop %.6g m (small-deflection formula %.6g)\n", b, exact,
                    q * 1e-4 / (8 * b));
        for (int n : {17, 33, 65}) {
            for (double back : {0.0, 0.5, 1.0}) {
                const double drop = cantilever_drop(n, 0.1, 0.025, b, back, false);
                std::printf("  %3d particles, clamp line %.1f spacings behind column 1, bends: %.6g (%+.3f%%)\n", n,
                            back, drop, 100 * (drop / exact - 1));
            }
            const double drop = cantilever_drop(n, 0.1, 0.025, b, 0.5, true);
            std::printf("  %3d particles, skip-one springs with the bends' k:         %.6g (%+.3f%%)\n", n, drop,
                        100 * (drop / exact - 1));
        }
    }
}

namespace {

struct Tensile {
    double stiffness;  // N/m: force per width per strain, from the stored energy 0.5 S strain^2 W L
    double poisson;    // contraction of the width at mid-length per strain
};

// A square sheet with `per_side` particles pulled to a strain of 1e-3 along u or v and settled
// (test::pulled_sheet); its stiffness from the elastic energy.
Tensile tensile_test(int per_side, bool along_u, glm::vec2 stretch, float shear) {
    const float side = 0.3f;
    MaterialSettings m;
    m.density = 0.15f;
    m.stretch = stretch;
    m.shear = shear;
    m.bending = glm::vec2(1e-5f);
    const double strain = 1e-3;
    // The slowest in-plane mode, w ~ pi sqrt(S / density) / side (1900 rad/s at 5000 N/m).
    const MassSpring sim = test::pulled_sheet(per_side, along_u, m, strain, std::min(stretch.x, stretch.y), 0.8f);
    Tensile out{};
    out.stiffness = 2.0 * sim.energy().spring_potential / (strain * strain * side * side);
    // Width at mid-length, across the middle column (along u) or row (along v).
    const int mid = per_side / 2;
    auto at = [&](int r, int c) { return sim.state().position.get(static_cast<std::size_t>(r) * per_side + c); };
    const double width = along_u ? at(per_side - 1, mid).y - at(0, mid).y : at(mid, per_side - 1).x - at(mid, 0).x;
    out.poisson = -(width / side - 1.0) / strain;
    return out;
}

}  // namespace

TEST_CASE("material: a sheet pulled along warp or weft has force per width per strain = material.stretch within 2% "
          "at 16, 32 and 64 particles a side", "[material]") {
    const glm::vec2 stretch{5000.0f, 2000.0f};
    const float shear = 100.0f;
    for (int n : {16, 32, 64}) {
        for (bool along_u : {true, false}) {
            const Tensile t = tensile_test(n, along_u, stretch, shear);
            const double target = along_u ? stretch.x : stretch.y;
            // The lattice's Poisson ratio C12 / C22 (material.hpp), measured at mid-length: the held edges keep
            // their width, so the middle of a square contracts a little less than a long strip would.
            Scene probe;
            probe.cloth.rows = probe.cloth.cols = n;
            probe.cloth.size = {0.3f, 0.3f};
            probe.material.stretch = stretch;
            probe.material.shear = shear;
            const SpringConstants k = spring_constants(probe.cloth, probe.material);
            const double poisson = along_u ? k.poisson_uv : k.poisson_vu;
            INFO(n << " a side, along " << (along_u ? "u" : "v") << ": " << t.stiffness << " N/m against " << target
                   << "; Poisson " << t.poisson << " against " << poisson);
            CHECK(std::abs(t.stiffness / target - 1.0) < 0.02);
            CHECK(t.poisson > 0.5 * poisson);
            CHECK(t.poisson < 1.05 * poisson);
        }
    }
}

TEST_CASE("material: every preset's lattice on square cells has its stretch along warp and weft (other direction "
          "free) and its shear, with no structural spring clamped to 0", "[material]") {
    // A clamped square's tensile test (above) measures between C11 - C12^2 / C22 and C11: for the knits, whose
    // shear is half their stretch (Poisson ratio G / C22 up to 0.4), that is 10-15% apart, so every preset is
    // checked on the stiffness tensor the springs assemble (square cells: C11 = a_u + G, C22 = a_v + G, C12 = G).
    for (const MaterialPreset& p : material_presets()) {
        INFO(p.name);
        Scene probe;
        probe.cloth.rows = probe.cloth.cols = 16;
        probe.cloth.size = {0.3f, 0.3f};
        probe.material.stretch = p.stretch;
        probe.material.shear = p.shear;
        const SpringConstants k = spring_constants(probe.cloth, probe.material);
        CHECK(k.note.empty());
        CHECK(k.structural.x > 0.0);
        CHECK(k.structural.y > 0.0);
        CHECK(k.shear == Approx(p.shear));
        const double c11 = k.structural.x + k.shear, c22 = k.structural.y + k.shear, c12 = k.shear;
        CHECK(c11 - c12 * c12 / c22 == Approx(p.stretch.x).epsilon(1e-6));
        CHECK(c22 - c12 * c12 / c11 == Approx(p.stretch.y).epsilon(1e-6));
    }
}

// Wang, O'Brien & Ramamoorthi 2011's released files (as ARCSim ships them): density, the zero-strain
// stretching row (c11, c12, c22, c33) and the lowest-curvature bending sample along warp (row 0) and weft
// (row 2).
struct WangFile {
    const char* name;
    double density, c11, c12, c22, c33, b_warp, b_weft;
};
constexpr WangFile kWangFiles[] = {
    {"11oz-black-denim", 0.324, 205.352005, 10.234077, 1013.88629, 53.387184, 64.196457e-6, 96.951576e-6},
    {"camel-ponte-roma", 0.284, 31.146198, -12.802702, 44.028667, 31.896357, 36.348366e-6, 37.157593e-6},
    {"gray-interlock", 0.187, 16.593832, -14.695990, 34.477123, 36.860302, 23.191698e-6, 14.267624e-6},
    {"ivory-rib-knit", 0.276, 42.871021, -0.234556, 65.166023, 83.175644, 46.237591e-6, 32.243889e-6},
    {"pink-ribbon-brown", 0.228, 151.503906, 106.028160, 244.830673, 30.250183, 117.070122e-6, 59.774277e-6},
    {"royal-target", 0.220, 2016.55456, 9.170511, 2034.97644, 104.759674, 125.409805e-6, 125.409805e-6},
    {"tango-red-jet-set", 0.113, 43.067627, 54.373299, 171.424835, 14.314700, 14.293814e-6, 20.345654e-6},
    {"white-dots-on-blk", 0.128, 2002.08618, 0.345588, 2027.48559, 19.189022, 51.713814e-6, 31.282822e-6},
    {"white-swim-solid", 0.204, 47.971176, 6.834521, 104.615456, 60.773663, 60.237942e-6, 51.018833e-6},
};

TEST_CASE("material: each Wang et al. preset is its file's zero-strain row as ARCSim's forces read it (tensile "
          "2 (c11 - c12^2 / c22), shear c33, bending b / 3), each Matsudaira et al. preset its KES B and weight, "
          "within their rounding", "[material]") {
    for (const WangFile& f : kWangFiles) {
        INFO(f.name);
        const MaterialPreset* p = find_material_preset(f.name);
        REQUIRE(p);
        // ARCSim doubles every entry after clamping it to 0 (dde.cpp); pulled along one direction with the other
        // free, the stress along the other vanishes: k0 - k1^2 / k2.
        const double c12 = std::max(f.c12, 0.0);
        CHECK(p->density == Approx(f.density).epsilon(0.005));
        CHECK(p->stretch.x == Approx(2.0 * (f.c11 - c12 * c12 / f.c22)).epsilon(0.005));
        CHECK(p->stretch.y == Approx(2.0 * (f.c22 - c12 * c12 / f.c11)).epsilon(0.005));
        CHECK(p->shear == Approx(f.c33).epsilon(0.005));
        CHECK(p->bending.x == Approx(f.b_warp / 3.0).epsilon(0.005));
        CHECK(p->bending.y == Approx(f.b_weft / 3.0).epsilon(0.005));
        CHECK_THAT(std::string(p->note), Catch::Contains("Wang et al. 2011"));
    }
    // Matsudaira et al. 2015, Table 1 (as transcribed; docs/MATERIAL.md): KES B in gf cm^2/cm and weight in
    // mg/cm^2, with the stretch and shear of the closest measured fabric, named in the note.
    const struct {
        const char* preset;
        double kes_b, weight;
        const char* closest;
    } matsudaira[] = {{"cotton-broadcloth", 0.118, 12.38, "royal-target"},
                      {"wool-tropical", 0.067, 16.29, "white-dots-on-blk"},
                      {"polyester-tropical", 0.077, 11.65, "white-dots-on-blk"},
                      {"polyester-faille", 0.019, 10.43, "tango-red-jet-set"}};
    for (const auto& m : matsudaira) {
        INFO(m.preset);
        const MaterialPreset* p = find_material_preset(m.preset);
        const MaterialPreset* closest = find_material_preset(m.closest);
        REQUIRE(p);
        REQUIRE(closest);
        CHECK(p->bending.x == Approx(m.kes_b * 9.80665e-5).epsilon(0.005));
        CHECK(p->bending.y == p->bending.x);  // one B per fabric in the table
        CHECK(p->density == Approx(m.weight * 0.01).epsilon(0.01));
        CHECK(p->stretch == closest->stretch);
        CHECK(p->shear == closest->shear);
        CHECK_THAT(std::string(p->note), Catch::Contains(m.closest) && Catch::Contains("Matsudaira et al. 2015"));
    }
}

TEST_CASE("material: spring constants reproduce the stretch, shear and bending the material asks for", "[material]") {
    Scene s;
    s.cloth.rows = 21;
    s.cloth.cols = 41;
    s.cloth.size = {1.0f, 0.5f};  // square cells of 0.025 m
    s.material.stretch = {4000.0f, 1000.0f};
    s.material.shear = 50.0f;
    s.material.bending = {2e-5f, 1e-5f};
    const SpringConstants k = spring_constants(s.cloth, s.material);
    const double h = 0.025;
    // Square cells: the diagonals give C11 = C22 = C12 = C66 = k_d = G; a_u = k_u.
    CHECK(k.shear == Approx(50.0));
    const double c11 = k.structural.x + k.shear, c22 = k.structural.y + k.shear, c12 = k.shear;
    CHECK(c11 - c12 * c12 / c22 == Approx(4000.0).epsilon(1e-9));
    CHECK(c22 - c12 * c12 / c11 == Approx(1000.0).epsilon(1e-9));
    CHECK(k.poisson_uv == Approx(c12 / c22));
    // A bend of k = B h_v / h_u^3 stores 0.5 B kappa^2 h_u h_v at |x_a - 2 x_m + x_b| = h^2 kappa.
    CHECK(k.bending.x == Approx(2e-5 / (h * h)).epsilon(1e-5));
    CHECK(k.bending.y == Approx(1e-5 / (h * h)).epsilon(1e-5));
    CHECK(k.total_mass == Approx(0.15 * 0.5).epsilon(1e-6));

    // Non-square cells: the same stretch and shear through other spring constants.
    s.cloth.rows = 11;  // 0.05 m along v, 0.025 m along u
    const SpringConstants r = spring_constants(s.cloth, s.material);
    const double hu = 0.025, hv = 0.05;
    const double C11 = r.structural.x * hu / hv + 50.0 * (hu / hv) * (hu / hv);
    const double C22 = r.structural.y * hv / hu + 50.0 * (hv / hu) * (hv / hu);
    CHECK(C11 - 2500.0 / C22 == Approx(4000.0).epsilon(1e-9));
    CHECK(C22 - 2500.0 / C11 == Approx(1000.0).epsilon(1e-9));
    CHECK(r.shear * 2.0 * hu * hv / (hu * hu + hv * hv) == Approx(50.0));
    CHECK(r.bending.x == Approx(2e-5 * hv / (hu * hu * hu)).epsilon(1e-5));
    CHECK(r.bending.y == Approx(1e-5 * hu / (hv * hv * hv)).epsilon(1e-5));

    CHECK(r.note.empty());
    // On long thin cells the diagonals alone are stiffer than the stretch asked along the short side: that
    // axis's structural springs are 0 and the note says what the stretch is instead.
    s.cloth.rows = 3;  // cells of 0.025 x 0.25 m
    s.material.shear = 3000.0f;
    const SpringConstants thin = spring_constants(s.cloth, s.material);
    CHECK(thin.structural.y == 0.0);
    CHECK(thin.structural.x > 0.0);
    CHECK_THAT(thin.note, Catch::Contains("along v") && Catch::Contains("closer to square"));
    s.cloth.rows = 1;
    CHECK_THROWS_WITH(spring_constants(s.cloth, s.material), Catch::Contains("at least 2 x 2"));
}

TEST_CASE("material: each particle carries a quarter of each cell around it, the cloth weighs density x area",
          "[material]") {
    Scene s = parse_scene("[cloth]\nrows = 5\ncols = 9\nsize = [0.8, 0.4]\n[material]\ndensity = 0.2\n", "t.toml");
    const MassSpring sim = build_simulation(s);
    const auto& m = sim.state().mass;
    const double cell = 0.2 * 0.1 * 0.1;
    CHECK(m[0] == Approx(cell / 4));         // corner
    CHECK(m[1] == Approx(cell / 2));         // edge
    CHECK(m[9 + 1] == Approx(cell));         // inside
    CHECK(m[4 * 9 + 8] == Approx(cell / 4));  // the far corner
    double total = 0.0;
    for (float x : m) total += x;
    CHECK(total == Approx(0.2 * 0.8 * 0.4).epsilon(1e-6));
    CHECK(s.cloth.mass == Approx(0.2f * 0.8f * 0.4f));  // cloth.mass shows the derived total
    CHECK(sim.bend_count() == 5 * 7 + 9 * 3);
    for (const Spring& spring : sim.topology().springs) CHECK(spring.kind != SpringKind::Bending);
}

TEST_CASE("material: a preset fills the fields a scene does not set, in any order, and --set takes a preset",
          "[material]") {
    const MaterialPreset* denim = find_material_preset("denim");
    REQUIRE(denim);
    for (const char* text : {"[material]\npreset = \"denim\"\nbending = 3e-5\n", "[material]\nbending = 3e-5\npreset = \"denim\"\n"}) {
        const Scene s = parse_scene(text, "t.toml");
        CHECK(s.material.enabled);
        CHECK(s.material.density == denim->density);
        CHECK(s.material.stretch == denim->stretch);
        CHECK(s.material.shear == denim->shear);
        CHECK(s.material.bending == glm::vec2(3e-5f));
    }
    // A per-spring scene that does not set its per-spring fields itself takes a preset from --set.
    Scene bundled = parse_scene("name = \"x\"\n", "t.toml");
    apply_override(bundled, "material.preset=polyester-faille");
    CHECK(bundled.material.density == find_material_preset("polyester-faille")->density);
    const MassSpring sim = build_simulation(bundled);
    CHECK(sim.bend_count() > 0);
    // Another preset later keeps the explicit field.
    apply_override(bundled, "material.stretch=[900, 300]");
    apply_override(bundled, "material.preset=cotton-broadcloth");
    CHECK(bundled.material.stretch == glm::vec2(900.0f, 300.0f));
    CHECK(bundled.material.density == find_material_preset("cotton-broadcloth")->density);
    // Every preset builds and steps.
    for (const MaterialPreset& p : material_presets()) {
        Scene s = load_scene("hanging");
        s.material = MaterialSettings{};  // the file's own fabric (cotton, its stretch set) gives way whole
        apply_override(s, "material.preset=" + std::string(p.name));
        REQUIRE(s.material.stretch == p.stretch);
        MassSpring run = build_simulation(s);
        run.set_substeps(auto_substeps(stability_limit(run), s.settings.integration.dt, 0.8f, 1));
        run.run_steps(10);
        INFO(p.name);
        CHECK(run.all_finite());
    }
}

TEST_CASE("material: an old preset name loads the fabric it stood for, saved under that fabric's name, with a note "
          "that says so, and a preset's own name gives no note", "[material]") {
    const struct {
        const char* old_name;
        const char* name;
    } renamed[] = {{"silk", "polyester-faille"}, {"wool-jersey", "gray-interlock"}, {"cotton", "cotton-broadcloth"},
                   {"polyester", "polyester-tropical"}};
    for (const auto& r : renamed) {
        INFO(r.old_name);
        const MaterialPreset* preset = find_material_preset(r.name);
        REQUIRE(preset);
        REQUIRE(find_material_preset(r.old_name) == preset);
        // From a file and from --set alike.
        Scene from_file = parse_scene(std::string("[material]\npreset = \"") + r.old_name + "\"\n", "t.toml");
        Scene from_set = parse_scene("name = \"x\"\n", "t.toml");
        apply_override(from_set, std::string("material.preset=") + r.old_name);
        for (const Scene* s : {&from_file, &from_set}) {
            CHECK(s->material.preset == r.name);
            CHECK(s->material.density == preset->density);
            CHECK(s->material.stretch == preset->stretch);
            CHECK(s->material.bending == preset->bending);
            REQUIRE(s->notes.size() == 1);
            CHECK_THAT(s->notes[0], Catch::Contains(std::string("\"") + r.old_name + "\" is an old name") &&
                                        Catch::Contains(std::string("loads \"") + r.name + "\""));
            // Written out, it reads back under the fabric's own name, with nothing to note.
            const Scene again = parse_scene(to_toml(*s), "again.toml");
            CHECK(again.material.preset == r.name);
            CHECK(again.notes.empty());
        }
    }
    // The two fabrics never measured are named nowhere as presets (wool tropical was: Matsudaira et al.'s B).
    for (const MaterialPreset& p : material_presets()) {
        CHECK(std::string(p.name).find("silk") == std::string::npos);
        CHECK(std::string(p.name).find("jersey") == std::string::npos);
        CHECK_FALSE(std::string(p.note).empty());
    }
    Scene plain = parse_scene("[material]\npreset = \"denim\"\n", "t.toml");
    CHECK(plain.notes.empty());
}

TEST_CASE("material: a scene that sets both forms is refused with the fields that clash", "[material]") {
    CHECK_THROWS_WITH(parse_scene("[cloth]\nmass = 0.3\n[springs]\nshear = 10\n[material]\npreset = \"denim\"\n", "a.toml"),
                      Catch::Contains("a.toml:") && Catch::Contains("cloth.mass, springs.shear") &&
                          Catch::Contains("material.preset"));
    Scene material = parse_scene("[material]\nstretch = 3000\n", "b.toml");
    CHECK_THROWS_WITH(apply_override(material, "springs.structural=5000"),
                      Catch::Contains("--set springs.structural=5000") && Catch::Contains("springs.structural") &&
                          Catch::Contains("material.stretch"));
    CHECK(material.per_spring_fields == 0);  // a refused --set changes nothing
    Scene per_spring = parse_scene("[springs]\nbending = 4\n", "c.toml");
    CHECK_THROWS_WITH(apply_override(per_spring, "material.density=0.2"), Catch::Contains("springs.bending"));
    // An unknown fabric: the line, and every preset the user may pick instead.
    std::string every_preset;
    for (const MaterialPreset& p : material_presets()) every_preset += (every_preset.empty() ? "" : ", ") + std::string(p.name);
    CHECK_THROWS_WITH(parse_scene("[material]\npreset = \"tweed\"\n", "d.toml"),
                      Catch::Contains("d.toml:2") && Catch::Contains("allowed: " + every_preset));
    // Changing rows and then cols one --set at a time passes through long thin cells: allowed, with a note.
    Scene knit = parse_scene("[cloth]\nsize = 0.3\nrows = 41\ncols = 41\n[material]\npreset = \"wool-jersey\"\n", "k.toml");
    apply_override(knit, "cloth.rows=81");
    CHECK(!spring_constants(knit.cloth, knit.material).note.empty());
    apply_override(knit, "cloth.cols=81");
    CHECK(spring_constants(knit.cloth, knit.material).note.empty());
    CHECK(build_simulation(knit).particle_count() == 81u * 81u);
    // Damping and the strain limit combine with either form.
    CHECK_NOTHROW(parse_scene("[springs]\ndamping = 1.0\nstrain_limit = 0.1\n[material]\npreset = \"silk\"\n", "e.toml"));
}

TEST_CASE("material: material.enabled = false returns a material scene to the per-spring form it derived",
          "[material]") {
    Scene s = load_scene("hanging");  // cotton, its stretch set
    REQUIRE(s.material.enabled);
    const SpringSettings derived = s.settings.springs;
    const float mass = s.cloth.mass;
    CHECK_THROWS_WITH(apply_override(s, "springs.structural=500"), Catch::Contains("material.stretch"));
    apply_override(s, "material.enabled=false");
    CHECK_FALSE(s.material.enabled);
    CHECK(s.material.preset.empty());
    CHECK(s.material.explicit_fields == 0);
    CHECK(s.settings.springs == derived);  // the same constants and mass, now per spring
    CHECK(s.cloth.mass == mass);
    apply_override(s, "springs.structural=500");
    CHECK(s.settings.springs.structural == glm::vec2(500.0f));
    const std::string text = to_toml(s);
    CHECK(text.find("[material]") == std::string::npos);
    CHECK(parse_scene(text, "back.toml").settings.springs == s.settings.springs);
    // On again: the material's fields as they stand, unless the scene now sets per-spring fields itself.
    CHECK_THROWS_WITH(apply_override(s, "material.enabled=true"), Catch::Contains("springs.structural"));
    // A file is not read in order: enabled = false beside another material field is refused, naming both.
    CHECK_THROWS_WITH(parse_scene("[material]\nenabled = false\npreset = \"denim\"\n", "f.toml"),
                      Catch::Contains("f.toml:3") && Catch::Contains("material.enabled = false") &&
                          Catch::Contains("material.preset"));
    CHECK_FALSE(parse_scene("[material]\nenabled = false\n", "g.toml").material.enabled);
    CHECK(parse_scene("[material]\nenabled = true\n", "h.toml").material.enabled);
}

TEST_CASE("material: derived per-spring values are not range-checked as if the user typed them", "[material]") {
    // A 1 mm cotton square weighs 1.2e-7 kg, below cloth.mass's minimum of 1e-6 kg: the mass is derived, the
    // size is in range, so the scene is accepted.
    Scene s = load_scene("hanging");
    apply_override(s, "cloth.size=0.001");
    CHECK(s.cloth.mass == Approx(s.material.density * 1e-6).epsilon(1e-3));
    CHECK(build_simulation(s).all_finite());
    // A value the user sets is still checked.
    CHECK_THROWS_WITH(apply_override(s, "material.density=1e9"), Catch::Contains("material.density"));
}

TEST_CASE("material: a scene written out reads back the same, with the derived per-spring values as comments",
          "[material]") {
    const Scene s = parse_scene("[cloth]\nrows = 12\ncols = 12\n[material]\npreset = \"gray-interlock\"\nshear = 20\n", "t.toml");
    const std::string text = to_toml(s);
    INFO(text);
    CHECK(text.find("preset = \"gray-interlock\"") != std::string::npos);
    CHECK(text.find("\nshear = 20.0") != std::string::npos);
    CHECK(text.find("density =") == std::string::npos);  // follows the preset
    CHECK(text.find("# structural = ") != std::string::npos);
    CHECK(text.find("# mass = ") != std::string::npos);
    const Scene back = parse_scene(text, "back.toml");
    CHECK(back.material == s.material);
    CHECK(back.settings.springs == s.settings.springs);
    CHECK(back.cloth.mass == s.cloth.mass);
    CHECK(to_toml(back) == text);
    // A per-spring scene writes no [material].
    CHECK(to_toml(parse_scene("[springs]\nshear = 9\n", "p.toml")).find("[material]") == std::string::npos);
}

namespace {

// `hanging` as a material at n particles a side: a 1 m square, released flat, held by two clips of 0.15 m
// (point pins are singular, docs/MATERIAL.md), settled with damping near critical for its swing. Returns
// the settled positions.
std::vector<glm::dvec3> hanging_settled(int n, double seconds = 5.0, float clip = 0.15f, float bending = 1e-4f,
                                        float damping = 6.0f, float stretch = 1000.0f, float tethers = 0.0f) {
    Scene s = load_scene("hanging");
    s.per_spring_fields = 0;
    s.cloth.rows = s.cloth.cols = n;
    s.material.enabled = true;
    s.material.preset.clear();
    s.material.density = 0.2f;
    s.material.stretch = glm::vec2(stretch);
    s.material.shear = 50.0f;
    s.material.bending = glm::vec2(bending);
    s.pins.preset_radius = clip;
    s.settings.springs.tether_strain = tethers;
    test::collider(s.settings.colliders, "ground").enabled = false;
    s.settings.springs.damping = damping;  // 6: 2 sqrt(g / L), the slowest swing at critical
    s.settings.solver.sleep_speed = 0.0f;
    s.settings.solver.threads = 1;
    MassSpring sim = build_simulation(s);
    sim.set_substeps(auto_substeps(stability_limit(sim), s.settings.integration.dt, 0.8f, 1));
    sim.run_steps(static_cast<long long>(seconds / s.settings.integration.dt));
    std::vector<glm::dvec3> out(sim.particle_count());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = sim.state().position.get(i);
    return out;
}

// The largest distance between two settled shapes of n and m particles a side, at the coarser grid's
// particles (the finer shape interpolated bilinearly at the same material point).
double shape_distance(const std::vector<glm::dvec3>& coarse, int n, const std::vector<glm::dvec3>& fine, int m) {
    double worst = 0.0;
    for (int r = 0; r < n; ++r) {
        for (int c = 0; c < n; ++c) {
            const double u = double(c) / (n - 1) * (m - 1), v = double(r) / (n - 1) * (m - 1);
            const int c0 = std::min(static_cast<int>(u), m - 2), r0 = std::min(static_cast<int>(v), m - 2);
            const double fu = u - c0, fv = v - r0;
            auto at = [&](int rr, int cc) { return fine[static_cast<std::size_t>(rr) * m + cc]; };
            const glm::dvec3 p = (1 - fv) * ((1 - fu) * at(r0, c0) + fu * at(r0, c0 + 1)) +
                                 fv * ((1 - fu) * at(r0 + 1, c0) + fu * at(r0 + 1, c0 + 1));
            worst = std::max(worst, glm::length(p - coarse[static_cast<std::size_t>(r) * n + c]));
        }
    }
    return worst;
}

}  // namespace

TEST_CASE("material: hanging settled at 17, 33 and 65 particles a side converges to one shape: the distance between "
          "successive resolutions at least halves per doubling (with the scene's tethers)", "[material][convergence]") {
    // Point pins (clip 0) as the bundled scene has them: nested grids, the pins on the same material points.
    // With the scene's tethers at 1% (measured 8.2, 3.2 mm, and 0.95 mm to 129): the factor 2.
    const auto a = hanging_settled(17, 5.0, 0.0f, 1e-4f, 6.0f, 1000.0f, 0.01f);
    const auto b = hanging_settled(33, 5.0, 0.0f, 1e-4f, 6.0f, 1000.0f, 0.01f);
    const auto c = hanging_settled(65, 5.0, 0.0f, 1e-4f, 6.0f, 1000.0f, 0.01f);
    const double d1 = shape_distance(a, 17, b, 33), d2 = shape_distance(b, 33, c, 65);
    INFO("tethers: 17 -> 33: " << d1 << " m, 33 -> 65: " << d2 << " m");
    CHECK(d1 < 0.02);
    CHECK(d2 <= 0.5 * d1);
    // Without them the strain at a point pin is singular and grows with the grid, and the shapes converge by
    // 0.64 and 0.57 per doubling only ("material study: resolution independence of hanging", docs/MATERIAL.md).
}

TEST_CASE("material study: resolution independence of hanging", "[material][.study]") {
    struct Case { double seconds; float clip, bending, damping, stretch, tethers; };
    for (const Case& c : {Case{5, 0.0f, 1e-4f, 6, 1000, 0.0f}, Case{5, 0.0f, 1e-4f, 6, 1000, 0.01f},
                          Case{5, 0.15f, 1e-4f, 6, 1000, 0.0f}, Case{5, 0.0f, 1e-5f, 6, 4000, 0.0f}}) {
        std::printf("settle %.0f s, clip %.2f m, B %g N m, damping %g, stretch %g, tethers %g:\n", c.seconds, c.clip,
                    c.bending, c.damping, c.stretch, c.tethers);
        const auto a = hanging_settled(17, c.seconds, c.clip, c.bending, c.damping, c.stretch, c.tethers);
        const auto b = hanging_settled(33, c.seconds, c.clip, c.bending, c.damping, c.stretch, c.tethers);
        const auto d = hanging_settled(65, c.seconds, c.clip, c.bending, c.damping, c.stretch, c.tethers);
        const auto e = hanging_settled(129, c.seconds, c.clip, c.bending, c.damping, c.stretch, c.tethers);
        std::printf("  17 -> 33: %.4g m, 33 -> 65: %.4g m, 65 -> 129: %.4g m\n", shape_distance(a, 17, b, 33),
                    shape_distance(b, 33, d, 65), shape_distance(d, 65, e, 129));
    }
}

TEST_CASE("material study: tensile test", "[material][.study]") {
    for (int n : {16, 32, 64}) {
        for (bool along_u : {true, false}) {
            const Tensile t = tensile_test(n, along_u, {5000.0f, 2000.0f}, 100.0f);
            std::printf("%2d a side, along %s: %.1f N/m (%+.3f%%), Poisson %.4f\n", n, along_u ? "u" : "v", t.stiffness,
                        100.0 * (t.stiffness / (along_u ? 5000.0 : 2000.0) - 1.0), t.poisson);
        }
    }
    Scene probe;
    probe.material.stretch = {5000.0f, 2000.0f};
    probe.material.shear = 100.0f;
    const SpringConstants k = spring_constants(probe.cloth, probe.material);
    std::printf("lattice Poisson ratios: %.4f (pulled along u), %.4f (along v)\n", k.poisson_uv, k.poisson_vu);
}
