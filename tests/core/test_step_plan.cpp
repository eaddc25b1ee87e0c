// The step plan: a stage that would do nothing is skipped, and skipping it changes no bit of the result
// (step_plan.hpp). Also what plan_step() and describe() report, and the per-stage profile.
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "collision/broad_phase.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/step_plan.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

using namespace clothsim;

namespace {

constexpr SolverMethod kMethods[] = {SolverMethod::Fast, SolverMethod::Textbook};

const char* method_name(SolverMethod m) { return m == SolverMethod::Fast ? "fast" : "textbook"; }

// Every particle's x, y and z equal (==) in both runs, and so is its motion over the last substep (the
// Verlet state: equal motion means the runs go on equal); the first particle that differs is reported.
void require_same_positions(const MassSpring& a, const MassSpring& b) {
    REQUIRE(a.particle_count() == b.particle_count());
    const State& sa = a.state();
    const State& sb = b.state();
    for (std::size_t i = 0; i < sa.size(); ++i) {
        const glm::vec3 p = sa.position.get(i), q = sb.position.get(i);
        const glm::vec3 m = sa.motion.get(i), n = sb.motion.get(i);
        if (p.x == q.x && p.y == q.y && p.z == q.z && m.x == n.x && m.y == n.y && m.z == n.z) continue;
        FAIL_CHECK("particle " << i << " differs: position (" << p.x << ", " << p.y << ", " << p.z << ") vs ("
                               << q.x << ", " << q.y << ", " << q.z << "), motion (" << m.x << ", " << m.y << ", "
                               << m.z << ") vs (" << n.x << ", " << n.y << ", " << n.z << ")");
        REQUIRE(false);
    }
}

// Whether any particle has moved away from where it started (so a comparison is not of two idle cloths).
bool moved_from(const MassSpring& sim, const std::vector<glm::vec3>& start) {
    for (std::size_t i = 0; i < sim.particle_count(); ++i) {
        if (sim.position(i) != start[i]) return true;
    }
    return false;
}

// A bundled drape scene, or "drape-cylinder": drape-sphere with a cylinder where the sphere was (its top
// where the sphere's top is). In the per-spring form: the broad phase is what differs, and 38 substeps a step
// keep these runs as short as they were before the scenes moved to [material].
Scene drape_scene(const std::string& name) {
    if (name != "drape-cylinder") return per_spring_scene(name);
    Scene s = per_spring_scene("drape-sphere");
    test::collider(s.settings.colliders, "sphere").enabled = false;
    test::collider(s.settings.colliders, "cylinder") = Collider{CylinderCollider{{0.0f, 0.425f, 0.0f}, 0.3f, 0.85f}, 0.4f, true, {}};
    return s;
}

void step_n(MassSpring& sim, int substeps) {
    for (int i = 0; i < substeps; ++i) sim.substep();
}

// The hanging cloth, small, with sleeping off so that only the stage under test differs between runs. In the
// per-spring form: these tests switch spring kinds off through settings.springs, which a material scene
// derives again from its [material] at every build.
Scene small_hanging(SolverMethod method, int n = 12) {
    Scene s = per_spring_scene("hanging");
    s.cloth.rows = n;
    s.cloth.cols = n;
    s.settings.solver.method = method;
    s.settings.solver.sleep_speed = 0.0f;
    return s;
}

// Turns a kind off (both axes).
void switch_off(SpringSettings& springs, SpringKind kind) {
    switch (kind) {
        case SpringKind::Structural: springs.structural = glm::vec2(0.0f); break;
        case SpringKind::Shear: springs.shear = 0.0f; break;
        case SpringKind::Bending: springs.bending = glm::vec2(0.0f); break;
    }
}

const StageStatus& status_of(const std::vector<StageStatus>& statuses, Stage stage) {
    const auto it = std::find_if(statuses.begin(), statuses.end(), [&](const StageStatus& s) { return s.stage == stage; });
    REQUIRE(it != statuses.end());
    return *it;
}

// A collider kind's index in the profile's per-kind block counts (collider.hpp: ColliderShape).
template <class Shape>
std::size_t kind_of() {
    return Collider::of(Shape{}).kind();
}

// The kinds the colliders stage tests under `plan`, as describe() lists them before the colon of its note
// ("sphere, plane"); empty when the stage does not run.
std::string projected_kinds(const StepPlan& plan, const Topology& topology, const SimulationSettings& settings) {
    const std::vector<StageStatus> statuses = describe(plan, topology, settings);
    const StageStatus& colliders = status_of(statuses, Stage::Colliders);
    return colliders.runs() ? colliders.note.substr(0, colliders.note.find(':')) : std::string();
}

}  // namespace

TEST_CASE("step_plan a spring kind with stiffness 0 moves the cloth bit for bit as a topology without that kind",
          "[step_plan]") {
    for (SolverMethod method : kMethods) {
        for (SpringKind kind : {SpringKind::Structural, SpringKind::Shear, SpringKind::Bending}) {
            INFO(method_name(method) << " solver, " << to_string(kind) << " springs");
            Scene scene = small_hanging(method);
            switch_off(scene.settings.springs, kind);
            MassSpring with_kind = build_simulation(scene);
            Topology without = with_kind.topology();
            std::erase_if(without.springs, [&](const Spring& s) { return s.kind == kind; });
            REQUIRE(without.springs.size() < with_kind.topology().springs.size());
            // Both from the same freshly built state: the constructor restarts from it at rest.
            MassSpring without_kind(without, with_kind.state(), with_kind.settings());
            const int k = static_cast<int>(kind);
            CHECK_FALSE(with_kind.plan().springs[k]);
            CHECK_FALSE(without_kind.plan().springs[k]);
            if (method == SolverMethod::Fast) {
                // A topology missing a whole spring kind is still a grid: the fast solver must run it.
                CHECK(without_kind.fast_solver_available());
                CHECK(without_kind.plan().path == StepPath::FastVerlet);
                CHECK(with_kind.plan().path == StepPath::FastVerlet);
            }
            const std::vector<glm::vec3> start = with_kind.positions();
            step_n(with_kind, 60);
            step_n(without_kind, 60);
            CHECK(moved_from(with_kind, start));
            require_same_positions(with_kind, without_kind);
        }
    }
}

TEST_CASE("step_plan fast and textbook solvers agree bit for bit for every set of skipped spring kinds",
          "[step_plan]") {
    for (unsigned mask = 0; mask < 8; ++mask) {
        // Kinds switched off from the start, and switched off live after 100 substeps with every kind on (the
        // fast solver's variant changes while it runs).
        for (int before : {0, 100}) {
            INFO("spring mask " << mask << " (bit 0 structural, 1 shear, 2 bending) after " << before
                                << " substeps with every kind");
            MassSpring runs[2] = {build_simulation(small_hanging(SolverMethod::Fast)),
                                  build_simulation(small_hanging(SolverMethod::Textbook))};
            for (MassSpring& sim : runs) {
                step_n(sim, before);
                test::edit_settings(sim, [&](SimulationSettings& s) {
                    for (SpringKind kind : {SpringKind::Structural, SpringKind::Shear, SpringKind::Bending}) {
                        if (!((mask >> static_cast<int>(kind)) & 1u)) switch_off(s.springs, kind);
                    }
                });
                sim.substep();  // the plan follows the settings from this step on
                CHECK(sim.plan().spring_mask() == mask);
                step_n(sim, 39);
            }
            CHECK(runs[0].plan().path == StepPath::FastVerlet);
            CHECK(runs[1].plan().path == StepPath::TextbookVerlet);
            require_same_positions(runs[0], runs[1]);
        }
    }
}

TEST_CASE("step_plan a wind stage exerting no force leaves positions bit-identical to skipping it", "[step_plan]") {
    for (SolverMethod method : kMethods) {
        INFO(method_name(method) << " solver");
        Scene still = small_hanging(method);
        still.settings.forces.wind = glm::vec3(0.0f);
        still.settings.forces.wind_model = WindModel::Triangles;
        Scene no_drag = still;  // air moving, but drag 0: the stage runs and adds zero forces
        no_drag.settings.forces.wind = {1.0f, 0.0f, 0.0f};
        no_drag.settings.forces.drag = 0.0f;
        Scene uniform = still;  // the uniform model always runs (it damps a moving cloth), here with drag 0
        uniform.settings.forces.wind_model = WindModel::Uniform;
        uniform.settings.forces.drag = 0.0f;

        MassSpring skipped = build_simulation(still);
        MassSpring runs = build_simulation(no_drag);
        MassSpring runs_uniform = build_simulation(uniform);
        CHECK_FALSE(skipped.plan().wind);
        CHECK(runs.plan().wind);
        CHECK(runs_uniform.plan().wind);
        const std::vector<glm::vec3> start = skipped.positions();
        for (MassSpring* sim : {&skipped, &runs, &runs_uniform}) step_n(*sim, 60);
        CHECK(skipped.profile().runs_of(Stage::Wind) == 0);
        CHECK(runs.profile().runs_of(Stage::Wind) == 60);
        CHECK(moved_from(skipped, start));
        require_same_positions(skipped, runs);
        require_same_positions(skipped, runs_uniform);
    }
}

TEST_CASE("step_plan a collider out of reach changes nothing and the broad phase culls every block", "[step_plan]") {
    for (SolverMethod method : kMethods) {
        INFO(method_name(method) << " solver");
        Scene without = small_hanging(method);
        Scene far = without;
        test::collider(far.settings.colliders, "sphere") = Collider{SphereCollider{{0.0f, -50.0f, 0.0f}, 1.0f}, 0.3f, true, {}};
        test::collider(far.settings.colliders, "cylinder") =
            Collider{CylinderCollider{{30.0f, 1.0f, 0.0f}, 1.0f, 2.0f}, 0.3f, true, {}};
        MassSpring a = build_simulation(without);
        MassSpring b = build_simulation(far);
        CHECK_FALSE(a.plan().solids);
        CHECK(projected_kinds(a.plan(), a.topology(), a.settings()).find("sphere") == std::string::npos);
        CHECK(projected_kinds(a.plan(), a.topology(), a.settings()).find("cylinder") == std::string::npos);
        CHECK(b.plan().colliders);
        CHECK(b.plan().solids);
        CHECK(projected_kinds(b.plan(), b.topology(), b.settings()).find("sphere") != std::string::npos);
        CHECK(projected_kinds(b.plan(), b.topology(), b.settings()).find("cylinder") != std::string::npos);
        step_n(a, 60);
        step_n(b, 60);
        require_same_positions(a, b);
        // Every block of the 12 x 12 grid offered every substep; none may touch a sphere 50 m below or a
        // cylinder 30 m to the side.
        CHECK(b.profile().runs_of(Stage::Colliders) == 60);
        for (std::size_t c : {kind_of<SphereCollider>(), kind_of<CylinderCollider>()}) {
            INFO("kind " << collider_kind_names()[c]);
            CHECK(b.profile().blocks_offered[c] == static_cast<long long>(12 * blocks_per_row(12) * 60));
            CHECK(b.profile().blocks_tested[c] == 0);
            CHECK(a.profile().blocks_offered[c] == 0);
        }
    }
}

TEST_CASE("step_plan the collision broad phase on or off gives bit-identical drapes", "[step_plan]") {
    for (const char* name : {"drape-sphere", "drape-cube", "drape-cylinder"}) {
        for (SolverMethod method : kMethods) {
            INFO(name << ", " << method_name(method) << " solver");
            Scene scene = drape_scene(name);
            scene.cloth.rows = 16;
            scene.cloth.cols = 16;
            scene.settings.solver.method = method;
            scene.settings.solver.sleep_speed = 0.0f;
            Scene off = scene;
            off.settings.solver.broad_phase = false;
            MassSpring culled = build_simulation(scene);
            MassSpring full = build_simulation(off);
            culled.run_steps(60);  // 1 s: the cloth has landed on the collider and drapes over it
            full.run_steps(60);
            require_same_positions(culled, full);
            const ColliderSettings& c = culled.settings().colliders;
            // The scene's solid shape (the sphere, the cube or the cylinder).
            const auto solid = std::find_if(c.shapes.begin(), c.shapes.end(),
                                            [](const Collider& x) { return x.enabled && !is_half_space(x); });
            REQUIRE(solid != c.shapes.end());
            const std::size_t which = solid->kind();
            const StepProfile& pc = culled.profile();
            const StepProfile& pf = full.profile();
            INFO("blocks tested " << pc.blocks_tested[which] << " of " << pc.blocks_offered[which]);
            CHECK(pc.blocks_offered[which] ==
                  static_cast<long long>(16 * blocks_per_row(16) * 60 * scene.settings.integration.substeps));
            CHECK(pc.blocks_tested[which] > 0);
            CHECK(pc.blocks_tested[which] < pc.blocks_offered[which]);
            CHECK(pf.blocks_tested[which] == pf.blocks_offered[which]);
            CHECK(pf.blocks_offered[which] == pc.blocks_offered[which]);
            const std::size_t ground = kind_of<PlaneCollider>();
            CHECK(pf.blocks_tested[ground] == pf.blocks_offered[ground]);  // the ground too
            // Draped: some particles rest on the collider.
            float closest = INFINITY;
            for (std::size_t i = 0; i < culled.particle_count(); ++i) {
                const glm::vec3 p = culled.position(i);
                closest = std::min(closest, signed_distance(*solid, p));
            }
            CHECK(closest < 2.0f * c.thickness);
        }
    }
}

TEST_CASE("step_plan the collision broad phase on or off gives bit-identical drapes with the velocity integrators",
          "[step_plan]") {
    // The velocity integrators move every particle before the collision stage too: the blocks' boxes of
    // the last substep no longer bound them, so the broad phase must not reuse them.
    for (Integrator integrator : {Integrator::SymplecticEuler, Integrator::Rk4, Integrator::Xpbd}) {
        INFO("integrator " << static_cast<int>(integrator));
        Scene scene = drape_scene("drape-sphere");
        scene.cloth.rows = 16;
        scene.cloth.cols = 16;
        scene.settings.integration.integrator = integrator;
        scene.settings.solver.sleep_speed = 0.0f;
        Scene off = scene;
        off.settings.solver.broad_phase = false;
        MassSpring culled = build_simulation(scene);
        MassSpring full = build_simulation(off);
        REQUIRE(culled.plan().path == StepPath::VelocityIntegrator);
        culled.run_steps(40);
        full.run_steps(40);
        require_same_positions(culled, full);
    }
}

TEST_CASE("step_plan plan_step follows each setting", "[step_plan]") {
    const MassSpring sim = build_simulation(small_hanging(SolverMethod::Fast));
    const Topology& t = sim.topology();
    SimulationSettings s = sim.settings();
    test::collider(s.colliders, "sphere").enabled = false;
    test::collider(s.colliders, "cube").enabled = false;
    test::collider(s.colliders, "ground").enabled = false;

    StepPlan p = plan_step(t, s, true);
    CHECK(p.path == StepPath::FastVerlet);
    CHECK(p.spring_mask() == 7u);
    CHECK_FALSE(p.wind);
    CHECK_FALSE(p.colliders);
    CHECK_FALSE(p.solids);
    CHECK_FALSE(p.strain_limit);
    CHECK_FALSE(p.speed_limit);
    CHECK_FALSE(p.may_sleep);  // small_hanging turns sleeping off

    CHECK(plan_step(t, s, false).path == StepPath::TextbookVerlet);  // no fast solver for this topology
    s.solver.method = SolverMethod::Textbook;
    CHECK(plan_step(t, s, true).path == StepPath::TextbookVerlet);
    s.solver.method = SolverMethod::Fast;
    for (Integrator i : {Integrator::SymplecticEuler, Integrator::Rk4, Integrator::ImplicitEuler, Integrator::Xpbd}) {
        s.integration.integrator = i;
        CHECK(plan_step(t, s, true).path == StepPath::VelocityIntegrator);
        CHECK(plan_step(t, s, false).path == StepPath::VelocityIntegrator);
    }
    s.integration.integrator = Integrator::Verlet;

    s.springs.strain_limit = 0.1f;
    CHECK(plan_step(t, s, true).strain_limit);
    s.springs.strain_limit = 0.0f;
    s.forces.max_speed = 5.0f;
    CHECK(plan_step(t, s, true).speed_limit);
    s.forces.max_speed = 0.0f;

    test::collider(s.colliders, "sphere").enabled = true;
    p = plan_step(t, s, true);
    CHECK((p.colliders && p.solids));
    CHECK(projected_kinds(p, t, s) == "sphere");
    test::collider(s.colliders, "sphere").enabled = false;
    test::collider(s.colliders, "cube").enabled = true;
    p = plan_step(t, s, true);
    CHECK((p.colliders && p.solids));
    CHECK(projected_kinds(p, t, s) == "box");
    test::collider(s.colliders, "cube").enabled = false;
    test::collider(s.colliders, "cylinder").enabled = true;
    p = plan_step(t, s, true);
    CHECK((p.colliders && p.solids));
    CHECK(projected_kinds(p, t, s) == "cylinder");
    test::collider(s.colliders, "cylinder").enabled = false;
    test::collider(s.colliders, "ground").enabled = true;
    p = plan_step(t, s, true);
    CHECK((p.colliders && !p.solids));
    CHECK(projected_kinds(p, t, s) == "plane");

    s.springs.shear = 0.0f;
    CHECK(plan_step(t, s, true).spring_mask() == 5u);
    s.springs.shear = 40.0f;
    Topology no_bending = t;  // stiffness > 0 but no springs of the kind: skipped too
    no_bending.spring_count_by_kind[static_cast<int>(SpringKind::Bending)] = 0;
    CHECK(plan_step(no_bending, s, true).spring_mask() == 3u);

    s.forces.wind = {2.0f, 0.0f, 0.0f};
    s.solver.sleep_speed = 0.002f;
    p = plan_step(t, s, true);
    CHECK(p.wind);
    CHECK_FALSE(p.may_sleep);  // moving air drives the cloth
    s.forces.wind = glm::vec3(0.0f);
    p = plan_step(t, s, true);
    CHECK_FALSE(p.wind);
    CHECK(p.may_sleep);
    s.forces.wind_model = WindModel::Uniform;  // drag toward still air acts on a moving cloth
    CHECK(plan_step(t, s, true).wind);
}

TEST_CASE("step_plan a setting applied to a live simulation replans at the point of change", "[step_plan]") {
    MassSpring sim = build_simulation(small_hanging(SolverMethod::Fast));
    REQUIRE(sim.plan().springs[2]);
    test::edit_settings(sim, [&](SimulationSettings& edit) { edit.springs.bending = glm::vec2(0.0f); });
    CHECK_FALSE(sim.plan().springs[2]);  // at once, not at the next step
    sim.substep();
    CHECK_FALSE(sim.plan().springs[2]);
    CHECK(sim.plan().path == StepPath::FastVerlet);

    test::edit_settings(sim, [&](SimulationSettings& edit) { edit.springs.strain_limit = 0.1f; });
    test::edit_settings(sim, [&](SimulationSettings& edit) { test::collider(edit.colliders, "sphere").enabled = true; });
    test::edit_settings(sim, [&](SimulationSettings& edit) { edit.integration.integrator = Integrator::Rk4; });
    sim.substep();
    CHECK(sim.plan().strain_limit);
    CHECK(sim.plan().solids);
    CHECK(projected_kinds(sim.plan(), sim.topology(), sim.settings()).find("sphere") != std::string::npos);
    CHECK(sim.plan().path == StepPath::VelocityIntegrator);

    test::edit_settings(sim, [&](SimulationSettings& edit) { edit.integration.integrator = Integrator::Verlet; });
    test::edit_settings(sim, [&](SimulationSettings& edit) { edit.solver.method = SolverMethod::Textbook; });
    sim.substep();
    CHECK(sim.plan().path == StepPath::TextbookVerlet);
}

TEST_CASE("step_plan describe lists every stage once and names the setting that skips one", "[step_plan]") {
    for (SolverMethod method : kMethods) {
        INFO(method_name(method) << " solver");
        Scene scene = small_hanging(method);
        scene.settings.springs.bending = glm::vec2(0.0f);
        scene.settings.forces.wind = glm::vec3(0.0f);
        scene.settings.springs.strain_limit = 0.0f;
        scene.settings.forces.max_speed = 0.0f;
        const MassSpring sim = build_simulation(scene);
        const std::vector<StageStatus> statuses = describe(sim.plan(), sim.topology(), sim.settings());
        REQUIRE(statuses.size() == kStageCount);
        for (std::size_t s = 0; s < kStageCount; ++s) {
            const Stage stage = static_cast<Stage>(s);
            INFO("stage " << stage_name(stage));
            CHECK(std::count_if(statuses.begin(), statuses.end(),
                                [&](const StageStatus& st) { return st.stage == stage; }) == 1);
        }
        for (const StageStatus& st : statuses) {
            INFO("stage " << stage_name(st.stage) << " " << state_name(st.state) << ": " << st.note);
            CHECK(st.stage != Stage::Count);
            if (!st.runs()) CHECK_FALSE(st.note.empty());  // skipped or fused: the note says why, or where
        }
        const StageStatus& wind = status_of(statuses, Stage::Wind);
        CHECK(wind.state == StageState::Skipped);
        CHECK(wind.note.find("forces.wind") != std::string::npos);
        const StageStatus& strain = status_of(statuses, Stage::StrainLimit);
        CHECK(strain.state == StageState::Skipped);
        CHECK(strain.note.find("springs.strain_limit") != std::string::npos);
        const StageStatus& speed = status_of(statuses, Stage::SpeedLimit);
        CHECK(speed.state == StageState::Skipped);
        CHECK(speed.note.find("forces.max_speed") != std::string::npos);
        const StageStatus& sleep = status_of(statuses, Stage::Sleep);
        CHECK(sleep.state == StageState::Skipped);
        CHECK(sleep.note.find("solver.sleep_speed") != std::string::npos);
        // The colliders stage runs for the ground, not for the sphere.
        CHECK(status_of(statuses, Stage::Colliders).state == StageState::Runs);
        CHECK(projected_kinds(sim.plan(), sim.topology(), sim.settings()) == "plane");
        // The springs' note says which kinds run and why bending does not.
        const StageStatus& springs = status_of(statuses, Stage::Springs);
        INFO("springs: " << springs.note);
        CHECK(springs.state == (method == SolverMethod::Fast ? StageState::Fused : StageState::Runs));
        CHECK(springs.note.find("bending: stiffness 0") != std::string::npos);
        CHECK(springs.note.find("structural") != std::string::npos);
        CHECK(status_of(statuses, Stage::Fast).state ==
              (method == SolverMethod::Fast ? StageState::Runs : StageState::Skipped));
        CHECK(status_of(statuses, Stage::Integrate).state ==
              (method == SolverMethod::Fast ? StageState::Fused : StageState::Runs));
    }
    // A kind missing from the topology is "no springs", not "stiffness 0"; moving air keeps the cloth awake.
    MassSpring sim = build_simulation(small_hanging(SolverMethod::Fast));
    Topology no_bending = sim.topology();
    std::erase_if(no_bending.springs, [](const Spring& s) { return s.kind == SpringKind::Bending; });
    SimulationSettings settings = sim.settings();
    settings.forces.wind = {1.0f, 0.0f, 0.0f};
    settings.solver.sleep_speed = 0.002f;
    const MassSpring without(no_bending, sim.state(), settings);
    const std::vector<StageStatus> statuses = describe(without.plan(), without.topology(), without.settings());
    CHECK(status_of(statuses, Stage::Springs).note.find("bending: no springs") != std::string::npos);
    CHECK(status_of(statuses, Stage::Wind).runs());
    CHECK(status_of(statuses, Stage::Sleep).state == StageState::Skipped);
    CHECK(status_of(statuses, Stage::Sleep).note.find("forces.wind") != std::string::npos);
    // No spring kind at all: the springs stage is skipped, and says why.
    settings.springs.structural = glm::vec2(0.0f);
    settings.springs.shear = 0.0f;
    const MassSpring none(no_bending, sim.state(), settings);
    const std::vector<StageStatus> none_statuses = describe(none.plan(), none.topology(), none.settings());
    const StageStatus& springs = status_of(none_statuses, Stage::Springs);
    CHECK(springs.state == StageState::Skipped);
    CHECK(springs.note.find("structural: stiffness 0") != std::string::npos);
}

TEST_CASE("step_plan the profile counts each stage that runs once per substep and skipped stages not at all",
          "[step_plan]") {
    constexpr int kSubsteps = 50;
    Scene scene = small_hanging(SolverMethod::Fast);
    scene.settings.forces.wind = glm::vec3(0.0f);
    scene.settings.springs.strain_limit = 0.0f;
    scene.settings.forces.max_speed = 0.0f;
    REQUIRE(test::collider(scene.settings.colliders, "ground").enabled);
    MassSpring sim = build_simulation(scene);
    step_n(sim, kSubsteps);
    const StepProfile& p = sim.profile();
    CHECK(p.substeps == kSubsteps);
    CHECK(p.slept_substeps == 0);
    for (Stage skipped : {Stage::Wind, Stage::StrainLimit, Stage::SpeedLimit, Stage::Springs, Stage::Integrate,
                          Stage::Sleep}) {
        INFO("stage " << stage_name(skipped));
        CHECK(p.runs_of(skipped) == 0);
        CHECK(p.ms_of(skipped) == 0.0);
    }
    for (Stage runs : {Stage::Fast, Stage::Colliders}) {
        INFO("stage " << stage_name(runs));
        CHECK(p.runs_of(runs) == kSubsteps);
        CHECK(p.ms_of(runs) > 0.0);
    }
    // The colliders stage tests the ground only: no block is offered to a sphere, a box or a cylinder.
    for (std::size_t kind : {kind_of<SphereCollider>(), kind_of<BoxCollider>(), kind_of<CylinderCollider>()}) {
        INFO("kind " << collider_kind_names()[kind]);
        CHECK(p.blocks_offered[kind] == 0);
        CHECK(p.blocks_tested[kind] == 0);
    }
    CHECK(p.blocks_offered[kind_of<PlaneCollider>()] == static_cast<long long>(12 * blocks_per_row(12) * kSubsteps));

    // The textbook path times its spring and integration stages instead of the fast solver's fused stage.
    MassSpring textbook = build_simulation(small_hanging(SolverMethod::Textbook));
    step_n(textbook, kSubsteps);
    CHECK(textbook.profile().runs_of(Stage::Springs) == kSubsteps);
    CHECK(textbook.profile().runs_of(Stage::Integrate) == kSubsteps);
    CHECK(textbook.profile().runs_of(Stage::Fast) == 0);

    // The sleep check runs once per step when the cloth may sleep.
    Scene sleepy = scene;
    sleepy.settings.solver.sleep_speed = 0.002f;
    MassSpring checked = build_simulation(sleepy);
    checked.run_steps(3);
    CHECK(checked.profile().runs_of(Stage::Sleep) == 3);
    CHECK(checked.profile().substeps == 3 * sleepy.settings.integration.substeps);

    // reset_profile starts again from zero; with profiling off nothing is timed.
    sim.reset_profile();
    CHECK(sim.profile().substeps == 0);
    CHECK(sim.profile().total_ms() == 0.0);
    sim.set_profiling(false);
    step_n(sim, kSubsteps);
    for (std::size_t s = 0; s < kStageCount; ++s) {
        INFO("stage " << stage_name(static_cast<Stage>(s)));
        CHECK(sim.profile().ms[s] == 0.0);
    }
    CHECK(sim.profile().total_ms() == 0.0);
    sim.set_profiling(true);
    step_n(sim, 1);
    CHECK(sim.profile().runs_of(Stage::Fast) == 1);
}

namespace {

// Per stage: describe() says it runs (as a timed stage of its own) exactly when the profile has timed it; a
// skipped stage, or one fused into another, shows 0 runs.
void check_describe_matches_profile(const MassSpring& sim) {
    const std::vector<StageStatus> statuses = describe(sim.plan(), sim.topology(), sim.settings());
    for (const StageStatus& st : statuses) {
        INFO("stage " << stage_name(st.stage) << " " << state_name(st.state) << " (" << st.note
                      << "): " << sim.profile().runs_of(st.stage) << " runs");
        CHECK(st.runs() == (sim.profile().runs_of(st.stage) > 0));
    }
}

// Every optional stage on: wind, the sphere, the cylinder, the strain and speed limits.
Scene busy(SolverMethod method) {
    Scene s = small_hanging(method);
    s.settings.forces.wind = {0.0f, 0.0f, 2.0f};
    test::collider(s.settings.colliders, "sphere") = Collider{SphereCollider{{0.0f, 1.0f, 0.0f}, 0.3f}, 0.3f, true, {}};
    test::collider(s.settings.colliders, "cylinder") = Collider{CylinderCollider{{0.3f, 0.6f, 0.0f}, 0.1f, 0.3f}, 0.3f, true, {}};
    s.settings.springs.strain_limit = 0.1f;
    s.settings.forces.max_speed = 20.0f;
    return s;
}

}  // namespace

TEST_CASE("step_plan describe and the profile agree on which stages ran", "[step_plan]") {
    for (SolverMethod method : kMethods) {
        for (bool everything : {false, true}) {
            INFO(method_name(method) << " solver, " << (everything ? "every stage on" : "defaults"));
            Scene scene = everything ? busy(method) : small_hanging(method);
            if (!everything) scene.settings.solver.sleep_speed = 0.002f;  // the sleep check runs
            MassSpring sim = build_simulation(scene);
            sim.run_steps(2);
            check_describe_matches_profile(sim);
        }
    }
}

TEST_CASE("step_plan the textbook path does not time the spring stage when every spring kind is skipped",
          "[step_plan]") {
    Scene scene = small_hanging(SolverMethod::Textbook);
    scene.settings.springs.structural = glm::vec2(0.0f);
    scene.settings.springs.shear = 0.0f;
    scene.settings.springs.bending = glm::vec2(0.0f);
    MassSpring sim = build_simulation(scene);
    REQUIRE_FALSE(sim.plan().any_springs());
    sim.run_steps(1);
    // step_profile.hpp: "a stage the plan skips is not timed at all and shows 0 with the plan's reason".
    CHECK(sim.profile().runs_of(Stage::Springs) == 0);
    CHECK(sim.profile().ms_of(Stage::Springs) == 0.0);
    check_describe_matches_profile(sim);
}

TEST_CASE("step_plan describe and the profile agree on which stages ran with a velocity integrator",
          "[step_plan]") {
    Scene scene = busy(SolverMethod::Fast);
    scene.settings.integration.integrator = Integrator::SymplecticEuler;
    MassSpring sim = build_simulation(scene);
    REQUIRE(sim.plan().path == StepPath::VelocityIntegrator);
    sim.run_steps(2);
    check_describe_matches_profile(sim);
}

TEST_CASE("step_plan penalty contact runs the contact force stage instead of the projection stages", "[step_plan]") {
    for (SolverMethod method : kMethods) {
        INFO(method_name(method) << " solver");
        Scene scene = load_scene("drape-sphere");
        scene.cloth.rows = scene.cloth.cols = 12;
        scene.settings.solver.method = method;
        scene.settings.solver.sleep_speed = 0.0f;
        scene.settings.colliders.contact = ContactModel::Penalty;
        MassSpring sim = build_simulation(scene);
        const StepPlan& plan = sim.plan();
        CHECK(plan.contact);
        CHECK_FALSE(plan.colliders);  // no sphere, cube or ground projection
        sim.run_steps(2);
        const long long substeps = 2LL * scene.settings.integration.substeps;
        CHECK(sim.profile().runs_of(Stage::Contact) == substeps);
        for (Stage skipped : {Stage::Colliders, Stage::BroadPhase}) {
            INFO("stage " << stage_name(skipped));
            CHECK(sim.profile().runs_of(skipped) == 0);
        }
        check_describe_matches_profile(sim);
        const std::vector<StageStatus> statuses = describe(sim.plan(), sim.topology(), sim.settings());
        CHECK(status_of(statuses, Stage::Contact).note.find("sphere, plane") != std::string::npos);
        CHECK(status_of(statuses, Stage::Contact).note.find("box") == std::string::npos);  // the cube is not enabled
        CHECK(status_of(statuses, Stage::Colliders).note.find("colliders.contact is penalty") != std::string::npos);

        // Back to projection through the one call: the projection stages run again, the contact stage not.
        test::edit_settings(sim, [](SimulationSettings& s) { s.colliders.contact = ContactModel::Projection; });
        CHECK_FALSE(sim.plan().contact);
        CHECK((sim.plan().colliders && sim.plan().solids));
        CHECK(projected_kinds(sim.plan(), sim.topology(), sim.settings()) == "sphere, plane");
        const std::vector<StageStatus> back = describe(sim.plan(), sim.topology(), sim.settings());
        CHECK(status_of(back, Stage::Contact).note == "colliders.contact is projection");
    }
    // A velocity integrator evaluates the contact inside its force calls; no thickness, no contact force.
    Scene scene = load_scene("drape-sphere");
    scene.cloth.rows = scene.cloth.cols = 12;
    scene.settings.colliders.contact = ContactModel::Penalty;
    scene.settings.integration.integrator = Integrator::Rk4;
    MassSpring rk4 = build_simulation(scene);
    rk4.run_steps(1);
    CHECK(status_of(describe(rk4.plan(), rk4.topology(), rk4.settings()), Stage::Contact).state == StageState::Fused);
    check_describe_matches_profile(rk4);
    SimulationSettings flat = rk4.settings();
    flat.colliders.thickness = 0.0f;
    CHECK_FALSE(plan_step(rk4.topology(), flat, true).contact);
    CHECK(status_of(describe(plan_step(rk4.topology(), flat, true), rk4.topology(), flat), Stage::Contact).note ==
          "colliders.thickness is 0");

    // The cylinder is one of the colliders the contact stage pushes with, and alone it is enough for one.
    SimulationSettings cylinder = rk4.settings();
    test::collider(cylinder.colliders, "cylinder").enabled = true;
    const std::vector<StageStatus> with = describe(plan_step(rk4.topology(), cylinder, true), rk4.topology(), cylinder);
    CHECK(status_of(with, Stage::Contact).note.find("sphere, cylinder, plane") != std::string::npos);
    CHECK(status_of(with, Stage::Colliders).note.find("colliders.contact is penalty") != std::string::npos);
    test::collider(cylinder.colliders, "sphere").enabled = test::collider(cylinder.colliders, "ground").enabled = false;
    const StepPlan only = plan_step(rk4.topology(), cylinder, true);
    CHECK(only.contact);
    CHECK_FALSE(only.colliders);
}
