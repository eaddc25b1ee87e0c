// Google Benchmark microbenchmarks of the step's kernels, on the hanging scene at several grid sizes:
// the textbook spring loop, one fast-solver substep (springs + integration + collisions fused), the
// textbook Verlet update, collisions with a sphere the cloth lies on, and the renderer's vertex normals. And
// what the fast solver's threads cost per substep with no work at all: the parallel region it opens each
// substep against the barriers one region per step would need instead (docs/PERFORMANCE.md).
#include "collision/colliders.hpp"
#include "clothsim/mesh_shapes.hpp"
#include "clothsim/normals.hpp"
#include "clothsim/scene.hpp"
#include "clothsim/stability.hpp"
#include "model/forces.hpp"
#include "integrators/verlet.hpp"

#include "per_spring_scenes.hpp"

#include <benchmark/benchmark.h>

namespace {

using namespace clothsim;

// hanging in its per-spring form (tests/fixtures/per_spring_scenes.hpp): the kernels' recorded workload, at 0.7 of the
// critical substep on the resized grid (at the file's substeps a large grid becomes non-finite in its first
// step, and NaN arithmetic is no measure of a kernel) and never asleep.
MassSpring hanging(int size, SolverMethod method, int threads) {
    Scene s = per_spring_scene("hanging");
    s.cloth.rows = size;
    s.cloth.cols = size;
    s.settings.solver.method = method;
    s.settings.solver.threads = threads;
    s.settings.solver.sleep_speed = 0.0f;
    const MassSpring probe = build_simulation(s);
    s.settings.integration.substeps = auto_substeps(stability_limit(probe), s.settings.integration.dt, 0.7f);
    return build_simulation(s);
}

void set_counters(benchmark::State& state, const MassSpring& sim) {
    state.counters["particles"] = static_cast<double>(sim.particle_count());
    state.counters["springs/s"] = benchmark::Counter(static_cast<double>(sim.spring_count()),
                                                     benchmark::Counter::kIsIterationInvariantRate);
}

void BM_TextbookSpringForces(benchmark::State& state) {
    MassSpring sim = hanging(static_cast<int>(state.range(0)), SolverMethod::Textbook, 1);
    sim.run_steps(1);  // a moving cloth, as in a run, rather than the exact rest state
    Vec3Array force;
    for (auto _ : state) {
        force.resize(sim.particle_count());
        accumulate_spring_forces(sim.topology(), sim.state().position, sim.settings().springs, force);
        benchmark::DoNotOptimize(force.x.data());
    }
    set_counters(state, sim);
}

void BM_FastSubstep(benchmark::State& state) {
    MassSpring sim = hanging(static_cast<int>(state.range(0)), SolverMethod::Fast, static_cast<int>(state.range(1)));
    for (auto _ : state) sim.substep();
    set_counters(state, sim);
}

void BM_TextbookSubstep(benchmark::State& state) {
    MassSpring sim = hanging(static_cast<int>(state.range(0)), SolverMethod::Textbook, 1);
    for (auto _ : state) sim.substep();
    set_counters(state, sim);
}

void BM_IntegrateVerlet(benchmark::State& state) {
    MassSpring sim = hanging(static_cast<int>(state.range(0)), SolverMethod::Textbook, 1);
    State st = sim.state();
    Vec3Array force;
    force.resize(st.size());
    for (auto _ : state) {
        integrate_verlet(st, force, {0.0f, -9.81f, 0.0f}, 0.2f, 1e-4f);
        benchmark::DoNotOptimize(st.position.x.data());
    }
    state.counters["particles/s"] =
        benchmark::Counter(static_cast<double>(st.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_CollideSphere(benchmark::State& state) {
    MassSpring sim = hanging(static_cast<int>(state.range(0)), SolverMethod::Textbook, 1);
    State st = sim.state();
    // A sphere through the middle of the cloth: about half the rows are near it.
    const Collider sphere{SphereCollider{st.position.get(st.size() / 2), 0.3f}, 0.3f, true, {}};
    for (auto _ : state) {
        collide(st, sphere, 0.005f);
        benchmark::DoNotOptimize(st.position.x.data());
    }
    state.counters["particles/s"] =
        benchmark::Counter(static_cast<double>(st.size()), benchmark::Counter::kIsIterationInvariantRate);
}

// Arg 1: 1 = the grid sweep (Topology::cell_triangles), 0 = the same triangles walked as a list.
void BM_VertexNormals(benchmark::State& state) {
    MassSpring sim = hanging(static_cast<int>(state.range(0)), SolverMethod::Fast, 1);
    Topology topology = sim.topology();
    topology.cell_triangles = state.range(1) != 0;
    std::vector<glm::vec3> normals;
    for (auto _ : state) {
        compute_vertex_normals(topology, sim.state().position, normals);
        benchmark::DoNotOptimize(normals.data());
    }
    state.counters["particles/s"] = benchmark::Counter(static_cast<double>(sim.particle_count()),
                                                       benchmark::Counter::kIsIterationInvariantRate);
}

// The synchronisation of one substep of FastSolver::step on `range(0)` threads, with no work: a parallel
// region with the barrier after the boundary spring rows inside ...
void BM_RegionPerSubstep(benchmark::State& state) {
    const int threads = static_cast<int>(state.range(0));
    for (auto _ : state) {
#pragma omp parallel num_threads(threads)
        {
#pragma omp barrier
        }
    }
    state.SetItemsProcessed(state.iterations());  // items/s: substeps per second, as below
}
// ... against what one region per step would still need each substep: that barrier, and one at the end of
// the substep before the next reads the positions another thread wrote (items/s: substeps per second).
void BM_BarriersPerSubstep(benchmark::State& state) {
    const int threads = static_cast<int>(state.range(0));
    constexpr int kSubsteps = 1000;
    for (auto _ : state) {
#pragma omp parallel num_threads(threads)
        for (int i = 0; i < kSubsteps; ++i) {
#pragma omp barrier
#pragma omp barrier
        }
    }
    state.SetItemsProcessed(state.iterations() * kSubsteps);
}

}  // namespace

// A mesh collider's tree (normals, edges, hierarchy: TriangleMesh's constructor) for the first `triangles` of
// an icosphere of 81,920 (issue 45: a 50,000-triangle mesh in under 50 ms).
void BM_MeshTree(benchmark::State& state) {
    static const TriangleMesh sphere = icosphere(0.35, 6);
    const auto count = static_cast<std::size_t>(state.range(0));
    for (auto _ : state) {
        state.PauseTiming();
        std::vector<glm::dvec3> vertices = sphere.vertices();
        std::vector<TriangleMesh::Triangle> triangles(sphere.triangles().begin(), sphere.triangles().begin() + static_cast<long>(count));
        state.ResumeTiming();
        TriangleMesh tree(std::move(vertices), std::move(triangles));
        benchmark::DoNotOptimize(tree);
    }
}

BENCHMARK(BM_TextbookSpringForces)->Arg(64)->Arg(128)->Arg(256);
BENCHMARK(BM_TextbookSubstep)->Arg(64)->Arg(128)->Arg(256);
BENCHMARK(BM_FastSubstep)->Args({64, 1})->Args({128, 1})->Args({256, 1})->Args({128, 2})->Args({256, 2})->UseRealTime();
BENCHMARK(BM_IntegrateVerlet)->Arg(64)->Arg(128)->Arg(256);
BENCHMARK(BM_CollideSphere)->Arg(64)->Arg(128)->Arg(256);
BENCHMARK(BM_VertexNormals)->Args({128, 0})->Args({128, 1})->Args({256, 0})->Args({256, 1})->UseRealTime();

// The cost bound of mesh contact (docs/COLLIDERS.md, "Measured"): one contact query per particle of a cloth
// resting on a sphere of radius 0.35 (a 128 x 128 grid over 1.2 m, the particles over the sphere placed at the
// 5 mm thickness from it, in the cloth's order), against `range(0)`: 0 the analytic sphere, 1 the icosphere
// of 81,920 triangles through its contact grid, 2 the floor of any search: the nearest triangle known
// beforehand, the particle moved into the mesh's coordinates and one closest-point test.
void BM_MeshContact(benchmark::State& state) {
    constexpr double kRadius = 0.35, kThickness = double(0.005f);
    static const auto mesh = std::make_shared<const TriangleMesh>(icosphere(kRadius, 6));
    static const std::vector<glm::dvec3> points = [] {
        std::vector<glm::dvec3> p;
        for (int r = 0; r < 128; ++r) {
            for (int c = 0; c < 128; ++c) {
                const double x = -0.6 + 1.2 * c / 127.0, z = -0.6 + 1.2 * r / 127.0;
                if (x * x + z * z >= kRadius * kRadius) continue;
                const glm::dvec3 d = glm::normalize(glm::dvec3(x, std::sqrt(kRadius * kRadius - x * x - z * z), z));
                p.push_back(glm::dvec3(0.0, 0.5, 0.0) + (kRadius + kThickness) * d);
            }
        }
        return p;
    }();
    MeshCollider m;
    m.mesh = mesh;
    m.position = {0.0f, 0.5f, 0.0f};
    const PlacedMesh at = placed(m, 0.005f);
    const SphereCollider sphere{{0.0f, 0.5f, 0.0f}, float(kRadius)};
    std::vector<std::uint32_t> nearest(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) nearest[i] = mesh->nearest(at.to_mesh(points[i]), 1.0)->triangle;
    const auto& v = mesh->vertices();
    const auto& t = mesh->triangles();
    const int kind = static_cast<int>(state.range(0));
    for (auto _ : state) {
        double sum = 0.0;
        for (std::size_t i = 0; i < points.size(); ++i) {
            if (kind == 0) {
                sum += contact(sphere, points[i], kThickness).depth;
            } else if (kind == 1) {
                sum += contact(at, points[i], kThickness).depth;
            } else {
                const glm::dvec3 q = at.to_mesh(points[i]);
                const auto& tri = t[nearest[i]];
                sum += glm::length(q - closest_point_on_triangle(q, v[tri[0]], v[tri[1]], v[tri[2]]));
            }
        }
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<long long>(points.size()));  // queries per second
}

BENCHMARK(BM_MeshContact)->Arg(0)->Arg(1)->Arg(2);
BENCHMARK(BM_MeshTree)->Arg(5120)->Arg(20480)->Arg(50000)->Arg(81920)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RegionPerSubstep)->Arg(2)->UseRealTime();
BENCHMARK(BM_BarriersPerSubstep)->Arg(2)->UseRealTime();

BENCHMARK_MAIN();
