// Nonlinear stretch (stretch_curve.hpp): the hinge-sum spring, its derivation from a material curve, the
// equilibrium it gives on every integrator, a tensile test through its knots, Wang et al.'s curves and the
// scene field.
#include "support.hpp"

#include "clothsim/material.hpp"
#include "clothsim/stability.hpp"
#include "clothsim/stretch_curve.hpp"

#include "model/forces.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <string>
#include <vector>

using namespace clothsim;

namespace {

SpringCurve make_curve(std::initializer_list<std::pair<float, float>> knots) {
    SpringCurve c;
    for (const auto& [strain, gain] : knots) {
        c.strain[c.knots] = strain;
        c.gain[c.knots] = gain;
        ++c.knots;
    }
    return c;
}

// The stretch e at which a spring of rest length `rest` and stiffness k pulls with `force`: the inverse of
// k t(e), by bisection (t increases).
double stretch_for(const SpringCurve& c, double k, double rest, double force) {
    double lo = 0.0, hi = rest;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (k * c.stretch_term(mid, rest) < force ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace

TEST_CASE("stretch curve: the spring's stretch term is the hinge sum, its tangent the gains passed, its energy the "
          "integral, and without knots it is the linear spring", "[stretch_curve]") {
    const SpringCurve linear{};
    CHECK(linear.stretch_term(0.013f, 0.1f) == 0.013f);
    CHECK(linear.tangent(0.5) == 1.0);
    const SpringCurve c = make_curve({{0.01f, 2.0f}, {0.03f, 5.0f}});
    const double rest = 0.1;
    // Below the first knot and in compression: linear.
    CHECK(c.stretch_term(0.0005, rest) == 0.0005);
    CHECK(c.stretch_term(-0.02, rest) == -0.02);
    // Between the knots: e + 2 (e - 0.001); past both: + 5 (e - 0.003).
    CHECK(c.stretch_term(0.002, rest) == Approx(0.002 + 2.0 * 0.001));
    CHECK(c.stretch_term(0.005, rest) == Approx(0.005 + 2.0 * 0.004 + 5.0 * 0.002));
    CHECK(c.tangent(0.005) == 1.0);
    CHECK(c.tangent(0.02) == 3.0);
    CHECK(c.tangent(0.05) == 8.0);
    CHECK(c.steepest() == 8.0);
    // The energy's derivative is the stretch term (central differences, at points off the knots).
    for (double e : {-0.004, 0.0007, 0.0021, 0.0049}) {
        const double d = 1e-7;
        const double slope = (c.energy_term(e + d, rest) - c.energy_term(e - d, rest)) / (2.0 * d);
        CHECK(slope == Approx(c.stretch_term(e, rest)).epsilon(1e-6));
    }
}

TEST_CASE("stretch curve: a material curve's factors become gains on the structural springs' share of the membrane",
          "[stretch_curve]") {
    // Factors 3 from 1% and 10 from 4%: the tangent's steps are 2 and 7 times the stretch, carried by the
    // springs' share a (the rest of the tensile stiffness comes from the diagonals).
    const std::vector<StretchSample> samples{{0.01f, 3.0f}, {0.04f, 10.0f}};
    const SpringCurve c = spring_curve(samples, 500.0, 400.0);
    REQUIRE(c.knots == 2);
    CHECK(c.strain[0] == 0.01f);
    CHECK(c.gain[0] == Approx(2.0 * 500.0 / 400.0));
    CHECK(c.gain[1] == Approx(7.0 * 500.0 / 400.0));
    CHECK(spring_curve(samples, 500.0, 0.0).knots == 0);  // no structural springs along that axis
    CHECK(stretch_samples_problem(samples).empty());
    CHECK_THAT(stretch_samples_problem({{0.02f, 2.0f}, {0.01f, 3.0f}}), Catch::Contains("sample 2") && Catch::Contains("increase"));
    CHECK_THAT(stretch_samples_problem({{0.0f, 2.0f}}), Catch::Contains("(0, 1]"));
    CHECK_THAT(stretch_samples_problem({{0.1f, -1.0f}}), Catch::Contains("factor"));
    CHECK_THAT(stretch_samples_problem(std::vector<StretchSample>(9, {0.1f, 1.0f})), Catch::Contains("at most 8"));
}

TEST_CASE("stretch curve: a hanging chain settles at the curve's inverse of each spring's load with every integrator",
          "[stretch_curve]") {
    // Eight particles of 10 g, 0.1 m apart, hanging from the top one: spring i carries the weight of the
    // particles below it, up to 0.69 N, which stretches a linear 100 N/m spring 6.9 mm (6.9%). The curve
    // triples the tangent from 1% and makes it 8 times from 2.5%: the lowest spring is on the first segment,
    // the top one past both knots (2.67 mm).
    const int n = 8;
    const double mass = 0.01, g = 9.81, k = 100.0, rest = 0.1;
    const SpringCurve curve = make_curve({{0.01f, 2.0f}, {0.025f, 5.0f}});
    struct Case {
        const char* name;
        Integrator integrator;
        SolverMethod method;
        int substeps;
    };
    const Case cases[] = {
        {"verlet, fast solver", Integrator::Verlet, SolverMethod::Fast, 40},
        {"verlet, textbook", Integrator::Verlet, SolverMethod::Textbook, 40},
        {"symplectic euler", Integrator::SymplecticEuler, SolverMethod::Textbook, 40},
        {"rk4", Integrator::Rk4, SolverMethod::Textbook, 20},
        {"implicit euler", Integrator::ImplicitEuler, SolverMethod::Textbook, 4},
        {"xpbd, grid form", Integrator::Xpbd, SolverMethod::Fast, 40},
        {"xpbd, list order", Integrator::Xpbd, SolverMethod::Textbook, 40},
        {"projective", Integrator::Projective, SolverMethod::Textbook, 4},
    };
    for (const Case& tc : cases) {
        Scene s = test::chain(n, static_cast<float>(rest), static_cast<float>(mass), static_cast<float>(k));
        s.pins.preset = PinPreset::TopCorners;
        s.settings.forces.gravity = {0.0f, -static_cast<float>(g), 0.0f};
        s.settings.springs.damping = 8.0f;
        s.settings.springs.stretch_curve[1] = curve;  // the chain's springs run along v
        s.settings.integration.integrator = tc.integrator;
        s.settings.solver.method = tc.method;
        s.settings.integration.substeps = tc.substeps;
        s.settings.solver.sleep_speed = 0.0f;
        MassSpring sim = build_simulation(s);
        sim.run_steps(600);  // 10 s: the slowest mode damped by e^-40
        INFO(tc.name);
        REQUIRE(sim.all_finite());
        double worst = 0.0, largest = 0.0;
        for (int i = 0; i + 1 < n; ++i) {
            const double load = (n - 1 - i) * mass * g;
            const double expected = stretch_for(curve, k, rest, load);
            const double got = glm::length(glm::dvec3(sim.position(i + 1) - sim.position(i))) - rest;
            worst = std::max(worst, std::abs(got - expected) / expected);
            largest = std::max(largest, expected);
        }
        INFO("largest relative error in a spring's stretch " << worst);
        // XPBD's single iteration per substep leaves a static bias of order k h^2 (w_a + w_b) (0.35% for the
        // linear spring here, more for the curve's stiffer secant): it converges as the substep shrinks.
        CHECK(worst < (tc.integrator == Integrator::Xpbd ? 5e-3 : 2e-3));
        CHECK(largest / rest > 0.025);  // the top spring is past both knots
        // The linear spring would stretch 6.9 mm at the top: the curve holds it to under half.
        CHECK(largest < 0.45 * (n - 1) * mass * g / k);
    }
}

namespace {

// A sheet pulled along u or v to `strain` through the curve's knots (test::pulled_sheet, settled at its
// steepest tangent): its elastic energy per area.
double tensile_energy(int per_side, bool along_u, const StretchCurve& curve, double strain) {
    MaterialSettings m;
    m.density = 0.15f;
    m.stretch = {400.0f, 200.0f};
    m.shear = 20.0f;
    m.bending = glm::vec2(1e-6f);
    m.stretch_curve = curve;
    m.explicit_fields |= kMaterialStretchCurve;
    double steepest = 1.0;
    for (const auto* samples : {&curve.u, &curve.v}) {
        for (const StretchSample& x : *samples) steepest = std::max(steepest, double(x.factor));
    }
    const MassSpring sim = test::pulled_sheet(per_side, along_u, m, strain, 200.0 * steepest, 0.5f);
    return sim.energy().spring_potential / (0.3 * 0.3);
}

// The energy per area of a tensile test of stretch S with the factors `samples`: the integral of the tension.
double curve_energy(double stretch, const std::vector<StretchSample>& samples, double strain) {
    double energy = 0.0, tension = 0.0, at = 0.0, slope = stretch;
    for (std::size_t j = 0; j <= samples.size(); ++j) {
        const double next = j < samples.size() ? std::min(double(samples[j].strain), strain) : strain;
        if (next > at) {
            energy += tension * (next - at) + 0.5 * slope * (next - at) * (next - at);
            tension += slope * (next - at);
            at = next;
        }
        if (j < samples.size()) slope = stretch * samples[j].factor;
    }
    return energy;
}

}  // namespace

TEST_CASE("stretch curve: a sheet pulled along warp or weft through the knots stores the material curve's energy "
          "within 2%", "[stretch_curve][material]") {
    StretchCurve curve;
    curve.u = {{0.005f, 3.0f}, {0.015f, 6.0f}};
    curve.v = {{0.01f, 4.0f}};
    for (bool along_u : {true, false}) {
        const double stretch = along_u ? 400.0 : 200.0;
        const std::vector<StretchSample>& samples = along_u ? curve.u : curve.v;
        for (double strain : {0.003, 0.012, 0.025}) {
            const double got = tensile_energy(24, along_u, curve, strain);
            const double expected = curve_energy(stretch, samples, strain);
            const double linear = 0.5 * stretch * strain * strain;
            INFO((along_u ? "warp" : "weft") << " at strain " << strain << ": " << got << " J/m^2, the curve's "
                                             << expected << ", linear " << linear);
            CHECK(got == Approx(expected).epsilon(0.02));
            if (strain > 0.02) CHECK(got > 1.5 * linear);  // the curve, not the linear spring
        }
    }
}

TEST_CASE("stretch curve: a Wang et al. preset's curve is their fitted model's tension: at 1/6 the stretched row "
          "alone, and its first segment the zero-strain stretch", "[stretch_curve][material]") {
    const MaterialPreset* p = find_material_preset("gray-interlock");
    REQUIRE(p);
    REQUIRE(p->stretching);
    const StretchCurve curve = preset_stretch_curve(*p);
    REQUIRE(curve.u.size() == 6);
    REQUIRE(curve.v.size() == 6);
    // At lambda = 7/6 the weft row (c11 127.44, c12 85.85, c22 405.87; gray-interlock.json's last row) alone:
    // S = 2 (c22 - c12^2 / c11), T = lambda S (lambda^2 - 1) / 2.
    const double lambda = 7.0 / 6.0;
    const double s_weft = 2.0 * (405.872833 - 85.848587 * 85.848587 / 127.443810);
    CHECK(wang_tension(*p->stretching, true, 1.0 / 6.0) == Approx(lambda * s_weft * (lambda * lambda - 1.0) / 2.0));
    CHECK(wang_stretch(*p->stretching, true) == Approx(p->stretch.y).epsilon(0.005));
    CHECK(wang_stretch(*p->stretching, false) == Approx(p->stretch.x).epsilon(0.005));
    // The curve integrated from the preset's stretch reaches the model's tension at each knot within the first
    // segment's offset (the model is already stiffer than S(1) inside the first 1%).
    for (bool weft : {false, true}) {
        const std::vector<StretchSample>& samples = weft ? curve.v : curve.u;
        const double s0 = wang_stretch(*p->stretching, weft);  // the factors' reference (the preset rounds it)
        double tension = s0 * samples[0].strain;
        for (std::size_t j = 0; j + 1 < samples.size(); ++j) {
            tension += s0 * samples[j].factor * (samples[j + 1].strain - samples[j].strain);
            const double model = wang_tension(*p->stretching, weft, samples[j + 1].strain);
            const double offset = wang_tension(*p->stretching, weft, samples[0].strain) - s0 * samples[0].strain;
            INFO((weft ? "weft" : "warp") << " at " << samples[j + 1].strain);
            CHECK(tension + offset == Approx(model).epsilon(1e-5));
        }
    }
    // The knit stiffens: its weft tangent at 15% is more than 10 times its zero-strain stretch.
    CHECK(curve.v[5].factor > 10.0f);
    // The linear presets carry no curve; every Wang preset does.
    CHECK(preset_stretch_curve(*find_material_preset("cotton-broadcloth")).empty());
    int curved = 0;
    for (const MaterialPreset& m : material_presets()) curved += !preset_stretch_curve(m).empty();
    CHECK(curved == 9);
}

TEST_CASE("stretch curve: the scene field loads, writes back, follows the preset, scales with the stretch and refuses "
          "bad curves by name", "[stretch_curve][scene]") {
    Scene s = parse_scene("[cloth]\nrows = 12\ncols = 12\n[material]\npreset = \"gray-interlock\"\n", "t.toml");
    REQUIRE(s.material.stretch_curve.u.size() == 6);
    const SpringCurve preset_u = s.settings.springs.stretch_curve[0];
    CHECK(preset_u.knots == 6);
    // {} turns the preset's curve off; the springs are linear.
    Scene linear = s;
    apply_override(linear, "material.stretch_curve={}");
    CHECK(linear.material.stretch_curve.empty());
    CHECK(linear.settings.springs.stretch_curve[0].knots == 0);
    // Twice the stretch: the same tangent factors of the membrane, so each knot adds twice the stiffness (on
    // square cells a_u = k_u: a gain times k_u is the added N/m).
    Scene doubled = s;
    apply_override(doubled, "material.stretch=[66.4, 138.0]");
    REQUIRE(doubled.settings.springs.stretch_curve[0].knots == 6);
    CHECK(doubled.settings.springs.stretch_curve[0].gain[3] * doubled.settings.springs.structural.x ==
          Approx(2.0 * preset_u.gain[3] * s.settings.springs.structural.x).epsilon(1e-4));
    // Its own curve, written back and read again.
    Scene own = parse_scene("[cloth]\nrows = 12\ncols = 12\n[material]\nstretch = 300\n"
                            "stretch_curve = { u = [[0.02, 3.0]], v = [[0.01, 2.0], [0.05, 9.0]] }\n",
                            "t.toml");
    CHECK(own.settings.springs.stretch_curve[1].knots == 2);
    const Scene again = parse_scene(to_toml(own), "again.toml");
    CHECK(again.material.stretch_curve == own.material.stretch_curve);
    CHECK(again.settings.springs.stretch_curve == own.settings.springs.stretch_curve);
    // Bad curves, each named.
    auto refusal = [](const std::string& curve) {
        try {
            parse_scene("[cloth]\nrows = 12\ncols = 12\n[material]\nstretch_curve = " + curve + "\n", "bad.toml");
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    CHECK_THAT(refusal("{ u = [[0.05, 2.0], [0.02, 3.0]] }"), Catch::Contains("material.stretch_curve.u") && Catch::Contains("sample 2"));
    CHECK_THAT(refusal("{ v = [[0.05, 0.0]] }"), Catch::Contains("material.stretch_curve.v") && Catch::Contains("factor"));
    CHECK_THAT(refusal("{ w = [[0.05, 2.0]] }"), Catch::Contains("unknown key 'w'"));
    CHECK_THAT(refusal("{ u = [[0.05]] }"), Catch::Contains("[strain, factor]"));
    CHECK_THAT(refusal("[1, 2]"), Catch::Contains("bad.toml"));
    // A mesh cloth's edges mix warp and weft: its curves are blends by warp level (stretch_curve.hpp). Along u
    // (the last level) the u curve with the whole membrane's gain, along v (the first) linear: the v part has no
    // knot of its own, the u knot's gain is 0 there. More than 8 distinct strains in u and v together do not fit.
    Scene mesh = load_scene("skirt");
    apply_override(mesh, "material.stretch_curve={ u = [[0.05, 2.0]] }");
    const SpringSettings& springs = mesh.settings.springs;
    CHECK(springs.stretch_curve[0].knots == 0);  // the grid's
    REQUIRE(springs.mesh_curve[kWarpLevels].knots == 1);
    CHECK(springs.mesh_curve[kWarpLevels].strain[0] == 0.05f);
    CHECK(springs.mesh_curve[kWarpLevels].gain[0] == Approx(1.0));
    CHECK(springs.mesh_curve[0].gain[0] == 0.0f);
    const double e_u = mesh.material.stretch.x, e_v = mesh.material.stretch.y;
    CHECK(springs.mesh_curve[kWarpLevels / 2].gain[0] == Approx(e_u / (e_u + e_v)));  // alpha at cos^2 = 1/2
    CHECK_THROWS_WITH(apply_override(mesh, "material.stretch_curve={ u = [[0.01, 2], [0.02, 3], [0.03, 4], [0.04, 5], "
                                           "[0.05, 6]], v = [[0.015, 2], [0.025, 3], [0.035, 4], [0.045, 5]] }"),
                      Catch::Contains("at most 8 distinct strains") && Catch::Contains("has 9"));
    // A Wang preset's curve on a mesh: its six strains are the same in u and v, one knot each.
    Scene knit = load_scene("skirt");
    apply_override(knit, "material.preset=gray-interlock");
    CHECK(knit.settings.springs.mesh_curve[kWarpLevels / 2].knots == 6);
    CHECK(has_mesh_curves(knit.settings.springs));
}
