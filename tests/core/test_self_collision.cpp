// Self-collision (self_collision.hpp): layers of one cloth stay apart and never cross.
#include "per_spring_scenes.hpp"
#include "support.hpp"

#include "clothsim/intersections.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/triangle_mesh.hpp"
#include "collision/self_collision.hpp"
#include "model/tearing.hpp"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

using namespace clothsim;

namespace {

// The smallest distance between two present particles that share no spring or bend, over all pairs
// (a uniform grid of cell `reach` finds every pair closer than reach).
double closest_strangers(const MassSpring& sim, const SelfCollision& springs_of, double reach) {
    const State& s = sim.state();
    const std::size_t n = s.size();
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    auto key = [&](std::size_t i) { return std::floor(s.position.x[i] / reach); };
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t u = 0; u < n; ++u) {
        const std::size_t i = order[u];
        if (s.pinned[i] == kAbsent) continue;
        for (std::size_t v = u + 1; v < n && key(order[v]) <= key(i) + 1; ++v) {
            const std::size_t j = order[v];
            if (s.pinned[j] == kAbsent) continue;
            if (springs_of.neighbours(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j))) continue;
            best = std::min(best, glm::length(s.position.get(i) - s.position.get(j)));
        }
    }
    return best;
}

// The smallest distance between the two particles of a fold pair (a bending spring's or a bend's ends), as
// a share of the distance the stage keeps between them (min(d, rest / 4)).
double fold_share(const MassSpring& sim, const SelfCollision& stage, double d, const DVec3Array& rest) {
    const DVec3Array& x = sim.state().position;
    double least = std::numeric_limits<double>::infinity();
    auto pair = [&](std::uint32_t i, std::uint32_t j) {
        REQUIRE(stage.fold_pair(i, j));
        REQUIRE(stage.fold_pair(j, i));
        least = std::min(least, glm::length(x.get(j) - x.get(i)) / stage.kept_distance(i, j, d, rest));
    };
    for (const Spring& s : sim.topology().springs) {
        if (s.kind == SpringKind::Bending) pair(s.a, s.b);
    }
    for (const Bend& b : sim.topology().bends) pair(b.a, b.b);
    return least;
}

// The scene with its grid cloth given as a mesh cloth (cloth.mesh) of the same particles and triangles, the
// vertices listed column by column: a mesh's runs of consecutive particles then lie across the grid's rows.
Scene as_mesh_in_column_order(Scene scene) {
    const MassSpring grid = build_simulation(scene);
    const int rows = grid.topology().rows, cols = grid.topology().cols;
    auto column_order = [&](std::uint32_t i) { return static_cast<std::uint32_t>((i % cols) * rows + i / cols); };
    std::vector<glm::dvec3> vertices(grid.particle_count());
    for (std::uint32_t i = 0; i < grid.particle_count(); ++i) vertices[column_order(i)] = grid.state().position.get(i);
    std::vector<TriangleMesh::Triangle> triangles;
    for (const auto& t : grid.topology().triangles) triangles.push_back({column_order(t[0]), column_order(t[1]), column_order(t[2])});
    scene.cloth.mesh = "column-order.obj";
    scene.cloth.mesh_data = std::make_shared<TriangleMesh>(std::move(vertices), std::move(triangles));
    scene.cloth.origin = {0.0f, 0.0f, 0.0f};
    return scene;
}

}  // namespace

TEST_CASE("self-collision: in pile and fold, strangers keep half the thickness, fold pairs half their kept distance, and no two triangles cross, every step",
          "[self-collision]") {
    for (const char* name : {"pile", "fold"}) {
        Scene scene = load_scene(name);
        REQUIRE(scene.settings.collision.self);
        MassSpring sim = build_simulation(scene);
        const SelfCollision springs_of(sim.topology(), sim.state().position);
        const double d = springs_of.contact_distance(sim.settings().collision);
        const DVec3Array rest = sim.state().position;  // built flat, at rest
        double closest = std::numeric_limits<double>::infinity(), closest_fold = closest;
        std::size_t crossings = 0;
        for (int step = 0; step < 150; ++step) {  // 2.5 s: falls, folds, settles
            sim.run_steps(1);
            REQUIRE(sim.all_finite());
            closest = std::min(closest, closest_strangers(sim, springs_of, d));
            closest_fold = std::min(closest_fold, fold_share(sim, springs_of, d, rest));
            crossings += intersecting_triangle_pairs(sim.topology(), sim.positions());
        }
        const long long contacts = sim.profile().self_contacts;
        INFO(name << ": contact distance " << d << " m, closest strangers " << closest << " m, fold pairs down to "
                  << closest_fold << " of their kept distance, " << contacts << " contacts");
        CHECK(contacts > 1000);  // the layers really met
        CHECK(closest >= 0.5 * d);
        CHECK(closest_fold >= 0.5);
        if (std::string(name) == "fold") {
            // The cloth still hangs over the bar (y = 1 m), its halves below it: it did not slide off.
            double mean_y = 0.0;
            for (const glm::vec3& p : sim.positions()) mean_y += p.y;
            mean_y /= static_cast<double>(sim.particle_count());
            INFO("fold: the cloth's mean height " << mean_y << " m");
            CHECK(mean_y > 0.6);
            CHECK(mean_y < 1.0);
        }
        CHECK(crossings == 0);
    }
}

TEST_CASE("self-collision: without it the same pile passes through itself", "[self-collision]") {
    // The checks above are not vacuous: with collision.self off, layers of `pile` come closer than half the
    // thickness and cross.
    Scene scene = load_scene("pile");
    scene.settings.collision.self = false;
    MassSpring sim = build_simulation(scene);
    const SelfCollision springs_of(sim.topology(), sim.state().position);
    const double d = springs_of.contact_distance(CollisionSettings{});
    double closest = std::numeric_limits<double>::infinity();
    std::size_t crossings = 0;
    for (int step = 0; step < 150; ++step) {
        sim.run_steps(1);
        closest = std::min(closest, closest_strangers(sim, springs_of, d));
        crossings += intersecting_triangle_pairs(sim.topology(), sim.positions());
    }
    CHECK(closest < 0.5 * d);
    CHECK(crossings > 0);
}

TEST_CASE("self-collision: fold pairs are the ends of bending springs and bends, both ways, on the grid, off it "
          "and after a tear", "[self-collision]") {
    for (const bool material : {false, true}) {  // skip-one bending springs, or bends
        Scene scene = material ? load_scene("falling") : per_spring_scene("falling");
        scene.cloth.rows = scene.cloth.cols = 8;
        MassSpring sim = build_simulation(scene);
        const DVec3Array& rest = sim.state().position;
        Topology topology = sim.topology();
        REQUIRE(topology.bends.empty() == !material);
        auto at = [&](int r, int c) { return static_cast<std::uint32_t>(topology.index(r, c)); };
        Topology listed = topology;  // the same links with no grid: the stage searches its lists
        listed.rows = listed.cols = 0;
        for (const Topology* t : {&topology, &listed}) {
            const SelfCollision stage(*t, rest);
            const double d = stage.contact_distance(sim.settings().collision), s = stage.spacing();
            INFO((material ? "bends" : "bending springs") << (t == &listed ? ", off the grid" : ", on the grid"));
            for (const auto& [a, b] : {std::pair{at(3, 2), at(3, 4)}, std::pair{at(2, 5), at(4, 5)}}) {
                CHECK(stage.fold_pair(a, b));
                CHECK(stage.fold_pair(b, a));
                CHECK(stage.kept_distance(a, b, d, rest) == Approx(0.5 * s).epsilon(1e-6));  // rest / 4 = s / 2 (s: a float rest length)
                CHECK(stage.kept_distance(b, a, d, rest) == Approx(0.5 * s).epsilon(1e-6));
            }
            // A structural and a shear neighbour: never kept apart. A stranger: min(d, rest) = d.
            CHECK_FALSE(stage.fold_pair(at(3, 2), at(3, 3)));
            CHECK(stage.kept_distance(at(3, 2), at(3, 3), d, rest) == 0.0);
            CHECK(stage.kept_distance(at(3, 2), at(4, 3), d, rest) == 0.0);
            CHECK_FALSE(stage.fold_pair(at(3, 2), at(4, 4)));
            CHECK(stage.kept_distance(at(3, 2), at(4, 4), d, rest) == Approx(d).epsilon(1e-9));
        }
        // Torn between (3, 3) and (3, 4): the fold pair across it, (3, 2)-(3, 4), is no longer linked and is a
        // stranger kept d apart; the one beside it, (2, 2)-(2, 4), is still a fold pair.
        SelfCollision stage(topology, rest);
        const std::size_t removed = break_springs(topology, [&](const Spring& spring) {
            return spring.kind == SpringKind::Structural && std::min(spring.a, spring.b) == at(3, 3) &&
                   std::max(spring.a, spring.b) == at(3, 4);
        });
        REQUIRE(removed >= 2);
        stage.update_neighbours(topology, rest);
        const double d = stage.contact_distance(sim.settings().collision);
        CHECK_FALSE(stage.fold_pair(at(3, 2), at(3, 4)));
        CHECK_FALSE(stage.neighbours(at(3, 2), at(3, 4)));
        CHECK(stage.kept_distance(at(3, 2), at(3, 4), d, rest) == Approx(d).epsilon(1e-9));
        CHECK(stage.fold_pair(at(2, 2), at(2, 4)));
    }
}

TEST_CASE("self-collision: two approaching strangers are pushed to the distance, their approach removed, momentum kept",
          "[self-collision]") {
    // The ends of a 13-particle chain (tiles of four particles: the ends are three tiles apart) meet head-on.
    Scene s = test::chain(13, 0.1f, 0.01f, 0.0f);
    s.settings.collision.self = true;
    s.settings.collision.self_thickness = 0.15f;
    s.settings.collision.self_friction = 0.0f;
    s.settings.solver.sleep_speed = 0.0f;
    MassSpring sim = build_simulation(s);
    REQUIRE_FALSE(SelfCollision(sim.topology(), sim.state().position).neighbours(0, 12));
    const double d = 0.15;
    // Put 12 just beside 0 and set the two moving towards each other.
    sim.set_particle(12, sim.position(0) + glm::vec3(0.9f * static_cast<float>(d), 0.0f, 0.0f), glm::vec3(-0.5f, 0.0f, 0.0f));
    sim.set_particle(0, sim.position(0), glm::vec3(0.5f, 0.0f, 0.0f));
    const glm::vec3 before = sim.momentum();
    sim.substep();
    const double gap = glm::length(sim.state().position.get(12) - sim.state().position.get(0));
    CHECK(gap == Approx(d).epsilon(1e-6));
    const glm::dvec3 approach = sim.state().motion.get(12) - sim.state().motion.get(0);
    CHECK(approach.x >= -1e-15);  // no longer closing
    CHECK(sim.profile().self_contacts == 1);
    CHECK(glm::length(sim.momentum() - before) < 1e-6f);
}

TEST_CASE("self-collision: between tests the stage resolves every touching pair a test would find, at every "
          "substep of pile and fold", "[self-collision]") {
    // The stage tests the tiles only when the closing since its last test may have spent the skin of its list
    // (or a fold threshold): at every substep, every pair closer than its kept distance (kept_distance) that a
    // test made there would find must be in the list it resolves. A stage of its own follows the simulation's
    // states substep by substep and is checked against a new stage, which tests at its first substep. The
    // simulation runs without self-collision, so that the particles move between two substeps by their
    // motion only (the stage's own pushes, which it counts, stay on its copy); its layers then meet and pass
    // through each other, which the list must follow all the same.
    for (const char* name : {"pile", "fold"}) {
        Scene scene = load_scene(name);
        scene.settings.collision.self = false;
        MassSpring sim = build_simulation(scene);
        const DVec3Array rest = sim.state().position;  // built flat, at rest
        SelfCollision stage(sim.topology(), rest);
        const CollisionSettings& settings = sim.settings().collision;
        const double d = stage.contact_distance(settings);
        long long checked = 0, from_list = 0, touching = 0;
        const long long substeps = 90LL * sim.settings().integration.substeps / test::kLoopShare;
        auto tested_blocks = [&] {
            long long sum = 0;
            for (const long long b : sim.profile().blocks_tested) sum += b;
            return sum;
        };
        for (long long k = 0; k < substeps; ++k) {
            const long long blocks = tested_blocks();
            sim.substep();
            // As MassSpring tells its own stage: a collider that tested particles may have pushed them outside
            // their motion; substeps without may be skipped beyond kSelfSkipMax.
            const bool uncounted = tested_blocks() > blocks;
            const State before = sim.state();
            State state = before;
            const SelfCollisionCounts counts = stage.collide(state, settings, rest, nullptr, uncounted);
            if (counts.clamped > 0) continue;  // the clamp moved particles before the list was made
            ++checked;
            if (counts.tiles > 0) continue;  // it tested too
            ++from_list;
            // What a test made now finds: a new stage's list, the pairs in it that touch.
            SelfCollision fresh(sim.topology(), rest);
            State tested = before;
            fresh.collide(tested, settings, rest);
            std::vector<std::uint64_t> touch;
            for (const std::uint64_t key : fresh.listed_pairs()) {
                const auto i = static_cast<std::uint32_t>(key >> 32), j = static_cast<std::uint32_t>(key);
                const double least = fresh.kept_distance(i, j, d, rest);
                if (glm::length(before.position.get(j) - before.position.get(i)) < least) touch.push_back(key);
            }
            touching += static_cast<long long>(touch.size());
            const std::vector<std::uint64_t>& listed = stage.listed_pairs();
            long long missing = 0;
            for (const std::uint64_t key : touch) missing += std::binary_search(listed.begin(), listed.end(), key) ? 0 : 1;
            if (missing > 0) {
                INFO(name << ": substep " << k << ", " << missing << " of " << touch.size() << " touching pairs not listed");
                CHECK(missing == 0);
                break;
            }
        }
        INFO(name << ": " << checked << " substeps checked, " << from_list << " resolved from an earlier test's list, "
                  << touching << " touching pairs there");
        CHECK(checked > substeps / 2);
        CHECK(from_list > checked / 10);  // substeps between tests use the list (what the test is about)
        CHECK(touching > 0);             // and the layers meet there
    }
}

TEST_CASE("self-collision: a flat cloth costs a box test and steps bit-identically to one without it", "[self-collision]") {
    Scene scene = load_scene("falling");
    scene.settings.collision.self = false;
    MassSpring plain = build_simulation(scene);
    scene.settings.collision.self = true;
    MassSpring with = build_simulation(scene);
    plain.run_steps(20);  // falling, flat, before it lands
    with.run_steps(20);
    CHECK(test::bit_identical(plain, with));
    CHECK(with.profile().self_tiles > 0);
    CHECK(with.profile().self_tiles_active == 0);
    CHECK(with.profile().self_contacts == 0);
    // A cloth that falls as a whole spends almost none of the budget a test leaves (conservative
    // advancement), and nothing moves it outside its motion: the box test runs once every kSelfSkipLimit
    // substeps.
    const long long tiles = static_cast<long long>((scene.cloth.rows + kSelfTile - 1) / kSelfTile) *
                            ((scene.cloth.cols + kSelfTile - 1) / kSelfTile);
    const long long tests = with.profile().self_tiles / tiles;
    INFO(tests << " box tests in " << with.profile().substeps << " substeps");
    CHECK(tests <= with.profile().substeps / kSelfSkipLimit + 1);
}

TEST_CASE("self-collision: the contact distance is the thickness, never less than the particle spacing", "[self-collision]") {
    Scene scene = load_scene("pile");
    MassSpring sim = build_simulation(scene);
    const SelfCollision self(sim.topology(), sim.state().position);
    CollisionSettings c;
    c.self_thickness = 0.0f;
    CHECK(self.contact_distance(c) == Approx(1.0 / 31.0));
    c.self_thickness = 0.01f;
    CHECK(self.contact_distance(c) == Approx(1.0 / 31.0));
    c.self_thickness = 0.05f;
    CHECK(self.contact_distance(c) == Approx(0.05));
}

TEST_CASE("self-collision: off by default, and the plan says so", "[self-collision]") {
    MassSpring sim = build_simulation(load_scene("hanging"));
    CHECK_FALSE(sim.plan().self_collision);
    bool said = false;
    for (const StageStatus& st : describe(sim.plan(), sim.topology(), sim.settings())) {
        if (st.stage == Stage::SelfCollision) said = !st.runs() && st.note == "collision.self is false";
    }
    CHECK(said);
}

TEST_CASE("self-collision: substeps with moves outside the motions are tested at least every kSelfSkipMax, others "
          "every kSelfSkipLimit", "[self-collision]") {
    // A flat cloth at rest: its motions spread nothing, so only the caps bring the next test.
    Scene scene = load_scene("falling");
    scene.cloth.v_axis = glm::vec3(0.0f, 0.0f, 1.0f);  // flat
    const MassSpring sim = build_simulation(scene);
    const DVec3Array rest = sim.state().position;
    State still = sim.state();
    for (std::size_t i = 0; i < still.size(); ++i) still.motion.set(i, glm::dvec3(0.0));
    CollisionSettings settings = sim.settings().collision;
    settings.self = true;
    auto tests = [&](bool uncounted, int substeps) {
        SelfCollision stage(sim.topology(), rest);
        int count = 0;
        for (int k = 0; k < substeps; ++k) {
            State state = still;
            count += stage.collide(state, settings, rest, nullptr, uncounted).tiles > 0 ? 1 : 0;
        }
        return count;
    };
    // A test, then kSelfSkipMax skips, then the next test: every (kSelfSkipMax + 1)th substep.
    CHECK(tests(true, 3 * (kSelfSkipMax + 1) + 1) == 4);
    CHECK(tests(false, 3 * (kSelfSkipMax + 1) + 1) == 1);
    CHECK(tests(false, 2 * (kSelfSkipLimit + 1) + 1) == 3);
}

TEST_CASE("self-collision: turned off and on again, it tests at its first substep", "[self-collision]") {
    // What the cloth did while the stage was off is in no budget: the list of the last test is stale.
    Scene scene = load_scene("falling");
    scene.cloth.v_axis = glm::vec3(0.0f, 0.0f, 1.0f);
    scene.settings.collision.self = true;
    MassSpring sim = build_simulation(scene);
    sim.run_steps(2);
    SimulationSettings off = sim.settings();
    off.collision.self = false;
    sim.apply(off);
    sim.run_steps(2);
    SimulationSettings on = off;
    on.collision.self = true;
    sim.apply(on);
    const long long tiles = sim.profile().self_tiles;
    sim.substep();
    CHECK(sim.profile().self_tiles > tiles);
}

TEST_CASE("self-collision: a mesh cloth in pile and fold, listed column by column, keeps strangers half the "
          "thickness apart and never crosses itself", "[self-collision]") {
    for (const char* name : {"pile", "fold"}) {
        MassSpring sim = build_simulation(as_mesh_in_column_order(load_scene(name)));
        REQUIRE(sim.topology().mesh);
        const SelfCollision springs_of(sim.topology(), sim.state().position);
        const double d = springs_of.contact_distance(sim.settings().collision);
        const DVec3Array rest = sim.state().position;  // built flat, at rest
        // Each hinge's far corners are a fold pair: down to what share of their kept distance they came.
        auto fold_share = [&] {
            double least = std::numeric_limits<double>::infinity();
            for (const Hinge& h : sim.topology().hinges) {
                REQUIRE(springs_of.fold_pair(h.v[2], h.v[3]));
                least = std::min(least, glm::length(sim.state().position.get(h.v[3]) - sim.state().position.get(h.v[2])) /
                                            springs_of.kept_distance(h.v[2], h.v[3], d, rest));
            }
            return least;
        };
        double closest = std::numeric_limits<double>::infinity(), closest_fold = closest;
        std::size_t crossings = 0;
        for (int step = 0; step < 150; ++step) {
            sim.run_steps(1);
            REQUIRE(sim.all_finite());
            closest = std::min(closest, closest_strangers(sim, springs_of, d));
            closest_fold = std::min(closest_fold, fold_share());
            crossings += intersecting_triangle_pairs(sim.topology(), sim.positions());
        }
        INFO(name << ": contact distance " << d << " m, closest strangers " << closest << " m, fold pairs down to "
                  << closest_fold << " of their kept distance, " << sim.profile().self_contacts << " contacts");
        CHECK(sim.profile().self_contacts > 1000);
        CHECK(closest >= 0.5 * d);
        CHECK(closest_fold >= 0.5);
        CHECK(crossings == 0);
    }
}
