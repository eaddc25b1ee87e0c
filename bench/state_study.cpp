// clothsim-state-study (issue 13): which representation of the Verlet state (position and motion =
// x - x_prev) to keep, chosen by measurement of accuracy and speed in one table.
//
// Every representation uses the same float forces (accumulate_spring_forces<float>, from the positions
// rounded to float) and the same float masses; they differ only in how position and motion are stored and
// updated:
//   A  float position, float motion (the state before issue 13): motion = motion*keep + a*h2, x += motion,
//      all in float.
//   B  A with a Kahan-compensated position (x_hi, x_lo floats); motion as A.
//   C  B with a compensated motion too (m_hi, m_lo floats): motion*keep as a double-float product (its
//      rounding error from fma, keep split into two floats), plus the float change by two-sum; the
//      position takes the two-float motion by two-sum. Under the project's flags (no -mfma) std::fma is a
//      call to libm's fmaf; C' gets the same error bits from an exact double product, timed apart.
//   D  double position and motion, float change (f*w + g)*h2 (the State of include/clothsim/state.hpp and
//      integrate_verlet; the study checks that its loop gives bit-identical positions to the library's).
//   E  double position and motion, everything in double (the change too).
//
// Measured: (1) max |x - x_ref| / cloth size on the smooth hanging scene after 15 steps of 1/60 s against
// the double-precision RK4 reference; (2) the relative error of a free fall's distance after 0.5 s at
// h = 1e-5 s; (3) the time of the update loop alone (16384 particles, a fixed force array).
//
//   nice build/release/bench/clothsim-state-study
#include "clothsim/reference.hpp"
#include "clothsim/scene.hpp"
#include "model/forces.hpp"
#include "integrators/verlet.hpp"

#include "per_spring_scenes.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

namespace {

using namespace clothsim;

// ---- The per-substep constants, in the precisions the representations use. ----
struct Coefficients {
    double keep;     // 1 - d (D, E)
    float keep_f;    // float(keep) (A, B)
    float keep_hi;   // keep = keep_hi + keep_lo (C)
    float keep_lo;
    float h2;        // h^2 / (1 + c h/2) rounded to float (A to D)
    double h2_d;     // the same in double (E)
};

Coefficients coefficients(double damping, double h) {
    const VerletCoefficients v = verlet_coefficients(damping, h);
    Coefficients c{};
    c.keep = v.keep;
    c.keep_f = static_cast<float>(v.keep);
    c.keep_hi = c.keep_f;
    c.keep_lo = static_cast<float>(v.keep - static_cast<double>(c.keep_hi));
    c.h2 = v.h2;
    c.h2_d = h * h / (1.0 + 0.5 * damping * h);
    return c;
}

// What every update reads: the float forces, float inverse masses, the pins and gravity.
struct Inputs {
    const Vec3Array* force;
    const AlignedVector<float>* inverse_mass;
    const std::vector<std::uint8_t>* pinned;
    glm::vec3 gravity;
};

const AlignedVector<float>& axis(const Vec3Array& v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }
float component(glm::vec3 v, int a) { return a == 0 ? v.x : a == 1 ? v.y : v.z; }

// Two-sum (Knuth): s + e == a + b exactly, s = fl(a + b).
inline void two_sum(float a, float b, float& s, float& e) {
    s = a + b;
    const float bb = s - a;
    e = (a - (s - bb)) + (b - bb);
}
// Fast two-sum (Dekker), for |a| >= |b|.
inline void fast_two_sum(float a, float b, float& s, float& e) {
    s = a + b;
    e = b - (s - a);
}

// ---- The representations. Each keeps three axes of its arrays; update() is one Verlet substep. ----
template <class T>
using Axes = std::array<std::vector<T>, 3>;

template <class T>
void resize_axes(Axes<T>& a, std::size_t n) {
    for (auto& v : a) v.assign(n, T(0));
}

double get(const DVec3Array& v, int a, std::size_t i) { return a == 0 ? v.x[i] : a == 1 ? v.y[i] : v.z[i]; }
double& ref(DVec3Array& v, int a, std::size_t i) { return a == 0 ? v.x[i] : a == 1 ? v.y[i] : v.z[i]; }

struct RepA {
    static constexpr const char* kName = "A: float x, float motion (old)";
    static constexpr int kBytes = 2 * 3 * 4;
    Axes<float> x, m;
    void init(const State& s) {
        resize_axes(x, s.size());
        resize_axes(m, s.size());
        for (int a = 0; a < 3; ++a) {
            for (std::size_t i = 0; i < s.size(); ++i) {
                x[a][i] = static_cast<float>(get(s.position, a, i));
                m[a][i] = static_cast<float>(get(s.motion, a, i));
            }
        }
    }
    double position(int a, std::size_t i) const { return x[a][i]; }
    void update(const Inputs& in, const Coefficients& c) {
        const std::size_t n = x[0].size();
        const float* w = in.inverse_mass->data();
        const std::uint8_t* pinned = in.pinned->data();
        for (int a = 0; a < 3; ++a) {
            const float* f = axis(*in.force, a).data();
            const float g = component(in.gravity, a);
            float* xa = x[a].data();
            float* ma = m[a].data();
            for (std::size_t i = 0; i < n; ++i) {
                if (pinned[i]) {
                    ma[i] = 0.0f;
                    continue;
                }
                const float change = (f[i] * w[i] + g) * c.h2;
                const float step = ma[i] * c.keep_f + change;
                ma[i] = step;
                xa[i] += step;
            }
        }
    }
};

struct RepB {
    static constexpr const char* kName = "B: Kahan float x (hi+lo), float motion";
    static constexpr int kBytes = 3 * 3 * 4;
    Axes<float> hi, lo, m;
    void init(const State& s) {
        resize_axes(hi, s.size());
        resize_axes(lo, s.size());
        resize_axes(m, s.size());
        for (int a = 0; a < 3; ++a) {
            for (std::size_t i = 0; i < s.size(); ++i) {
                const double p = get(s.position, a, i);
                hi[a][i] = static_cast<float>(p);
                lo[a][i] = static_cast<float>(p - hi[a][i]);
                m[a][i] = static_cast<float>(get(s.motion, a, i));
            }
        }
    }
    double position(int a, std::size_t i) const { return double(hi[a][i]) + double(lo[a][i]); }
    void update(const Inputs& in, const Coefficients& c) {
        const std::size_t n = hi[0].size();
        const float* w = in.inverse_mass->data();
        const std::uint8_t* pinned = in.pinned->data();
        for (int a = 0; a < 3; ++a) {
            const float* f = axis(*in.force, a).data();
            const float g = component(in.gravity, a);
            float* xh = hi[a].data();
            float* xl = lo[a].data();
            float* ma = m[a].data();
            for (std::size_t i = 0; i < n; ++i) {
                if (pinned[i]) {
                    ma[i] = 0.0f;
                    continue;
                }
                const float change = (f[i] * w[i] + g) * c.h2;
                const float step = ma[i] * c.keep_f + change;
                ma[i] = step;
                // Kahan: carry what the rounded sum lost into the next substep.
                const float y = step + xl[i];
                const float t = xh[i] + y;
                xl[i] = y - (t - xh[i]);
                xh[i] = t;
            }
        }
    }
};

// kFma: the product's rounding error from std::fma (without -mfma in the project's flags a call to libm's
// fmaf); otherwise from the float x float product, which is exact in double (48 significant bits), rounded
// back to float (exact too): the same bits, no call.
template <bool kFma>
struct RepC {
    static constexpr const char* kName = kFma ? "C: two-float x, two-float motion"
                                              : "C': C with the product error from an exact double product";
    static constexpr int kBytes = 4 * 3 * 4;
    Axes<float> hi, lo, mhi, mlo;
    void init(const State& s) {
        resize_axes(hi, s.size());
        resize_axes(lo, s.size());
        resize_axes(mhi, s.size());
        resize_axes(mlo, s.size());
        for (int a = 0; a < 3; ++a) {
            for (std::size_t i = 0; i < s.size(); ++i) {
                const double p = get(s.position, a, i);
                hi[a][i] = static_cast<float>(p);
                lo[a][i] = static_cast<float>(p - hi[a][i]);
                const double q = get(s.motion, a, i);
                mhi[a][i] = static_cast<float>(q);
                mlo[a][i] = static_cast<float>(q - mhi[a][i]);
            }
        }
    }
    double position(int a, std::size_t i) const { return double(hi[a][i]) + double(lo[a][i]); }
    void update(const Inputs& in, const Coefficients& c) {
        const std::size_t n = hi[0].size();
        const float* w = in.inverse_mass->data();
        const std::uint8_t* pinned = in.pinned->data();
        for (int a = 0; a < 3; ++a) {
            const float* f = axis(*in.force, a).data();
            const float g = component(in.gravity, a);
            float* xh = hi[a].data();
            float* xl = lo[a].data();
            float* mh = mhi[a].data();
            float* ml = mlo[a].data();
            for (std::size_t i = 0; i < n; ++i) {
                if (pinned[i]) {
                    mh[i] = 0.0f;
                    ml[i] = 0.0f;
                    continue;
                }
                const float change = (f[i] * w[i] + g) * c.h2;
                // (mh + ml)(keep_hi + keep_lo): the product's rounding error exactly from fma, the cross terms
                // in float.
                const float p = mh[i] * c.keep_hi;
                const float p_err = kFma ? std::fma(mh[i], c.keep_hi, -p)
                                         : static_cast<float>(double(mh[i]) * double(c.keep_hi) - double(p));
                float s, s_err;
                two_sum(p, change, s, s_err);
                const float low = (p_err + s_err) + (mh[i] * c.keep_lo + ml[i] * c.keep_hi);
                float step_hi, step_lo;
                fast_two_sum(s, low, step_hi, step_lo);
                mh[i] = step_hi;
                ml[i] = step_lo;
                // (xh + xl) + (step_hi + step_lo), renormalised.
                float t, t_err;
                two_sum(xh[i], step_hi, t, t_err);
                t_err += xl[i] + step_lo;
                fast_two_sum(t, t_err, xh[i], xl[i]);
            }
        }
    }
};

struct RepD {
    static constexpr const char* kName = "D: double x, double motion, float change (chosen)";
    static constexpr int kBytes = 2 * 3 * 8;
    Axes<double> x, m;
    void init(const State& s) {
        resize_axes(x, s.size());
        resize_axes(m, s.size());
        for (int a = 0; a < 3; ++a) {
            for (std::size_t i = 0; i < s.size(); ++i) {
                x[a][i] = get(s.position, a, i);
                m[a][i] = get(s.motion, a, i);
            }
        }
    }
    double position(int a, std::size_t i) const { return x[a][i]; }
    void update(const Inputs& in, const Coefficients& c) {
        const std::size_t n = x[0].size();
        const float* w = in.inverse_mass->data();
        const std::uint8_t* pinned = in.pinned->data();
        for (int a = 0; a < 3; ++a) {
            const float* f = axis(*in.force, a).data();
            const float g = component(in.gravity, a);
            double* xa = x[a].data();
            double* ma = m[a].data();
            for (std::size_t i = 0; i < n; ++i) {
                if (pinned[i]) {
                    ma[i] = 0.0;
                    continue;
                }
                const float change = (f[i] * w[i] + g) * c.h2;
                const double step = ma[i] * c.keep + static_cast<double>(change);
                ma[i] = step;
                xa[i] += step;
            }
        }
    }
};

struct RepE {
    static constexpr const char* kName = "E: double x, double motion, double change";
    static constexpr int kBytes = 2 * 3 * 8;
    Axes<double> x, m;
    void init(const State& s) {
        resize_axes(x, s.size());
        resize_axes(m, s.size());
        for (int a = 0; a < 3; ++a) {
            for (std::size_t i = 0; i < s.size(); ++i) {
                x[a][i] = get(s.position, a, i);
                m[a][i] = get(s.motion, a, i);
            }
        }
    }
    double position(int a, std::size_t i) const { return x[a][i]; }
    void update(const Inputs& in, const Coefficients& c) {
        const std::size_t n = x[0].size();
        const float* w = in.inverse_mass->data();
        const std::uint8_t* pinned = in.pinned->data();
        for (int a = 0; a < 3; ++a) {
            const float* f = axis(*in.force, a).data();
            const double g = component(in.gravity, a);
            double* xa = x[a].data();
            double* ma = m[a].data();
            for (std::size_t i = 0; i < n; ++i) {
                if (pinned[i]) {
                    ma[i] = 0.0;
                    continue;
                }
                const double change = (double(f[i]) * double(w[i]) + g) * c.h2_d;
                const double step = ma[i] * c.keep + change;
                ma[i] = step;
                xa[i] += step;
            }
        }
    }
};

template <class Rep>
void fill_positions(const Rep& rep, DVec3Array& out) {
    for (int a = 0; a < 3; ++a) {
        for (std::size_t i = 0; i < out.size(); ++i) ref(out, a, i) = rep.position(a, i);
    }
}

template <class Rep>
std::vector<glm::dvec3> positions_of(const Rep& rep, std::size_t n) {
    std::vector<glm::dvec3> p(n);
    for (std::size_t i = 0; i < n; ++i) p[i] = {rep.position(0, i), rep.position(1, i), rep.position(2, i)};
    return p;
}

// ---- (1) Accuracy on the smooth scene. ----
constexpr float kStep = 1.0f / 60.0f;  // s
constexpr int kSteps = 15;
constexpr std::array<int, 3> kSubsteps = {136, 544, 4096};

Scene smooth_scene() {
    Scene s = per_spring_scene("hanging");  // the per-spring cloth docs/ACCURACY.md's figures measured
    s.cloth.rows = s.cloth.cols = 32;
    s.settings.colliders.shapes.clear();  // no ground
    s.settings.integration.dt = kStep;
    return s;
}

// The start shared by every representation: build_simulation's particles at rest, the second-order start
// motion -a0 h^2/2 (in double, as start_verlet computes it) from the float start forces.
State start_state(const MassSpring& sim, double h) {
    State s = sim.state();
    Vec3Array force;
    force.resize(s.size());
    accumulate_spring_forces(sim.topology(), s.position, sim.settings().springs, force);
    start_verlet(s, std::vector<glm::dvec3>(s.size(), glm::dvec3(0.0)), force, sim.settings().forces.gravity,
                 sim.settings().springs.damping, h);
    return s;
}

template <class Rep>
std::vector<glm::dvec3> run_scene(const MassSpring& sim, int substeps) {
    const double h = static_cast<double>(kStep) / substeps;  // as MassSpring::substep_length
    const State s0 = start_state(sim, h);
    const SimulationSettings& settings = sim.settings();
    const Coefficients c = coefficients(settings.springs.damping, h);
    Rep rep;
    rep.init(s0);
    Vec3Array force;
    DVec3Array position;
    position.resize(s0.size());
    const Inputs in{&force, &s0.inverse_mass, &s0.pinned, settings.forces.gravity};
    const long long total = static_cast<long long>(kSteps) * substeps;
    for (long long k = 0; k < total; ++k) {
        fill_positions(rep, position);
        force.resize(s0.size());
        accumulate_spring_forces(sim.topology(), position, settings.springs, force);
        rep.update(in, c);
    }
    return positions_of(rep, s0.size());
}

// D through the library's integrate_verlet, for the bit-identity check of RepD's loop.
std::vector<glm::dvec3> run_scene_library(const MassSpring& sim, int substeps) {
    const double h = static_cast<double>(kStep) / substeps;
    State s = start_state(sim, h);
    const SimulationSettings& settings = sim.settings();
    Vec3Array force;
    const long long total = static_cast<long long>(kSteps) * substeps;
    for (long long k = 0; k < total; ++k) {
        force.resize(s.size());
        accumulate_spring_forces(sim.topology(), s.position, settings.springs, force);
        integrate_verlet(s, force, settings.forces.gravity, settings.springs.damping, h);
    }
    std::vector<glm::dvec3> p(s.size());
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = s.position.get(i);
    return p;
}

// ---- (2) Free fall: one particle from 1.6 m, no springs, no damping, h = 1e-5 s, 5e4 substeps. ----
template <class Rep>
double free_fall_error() {
    constexpr double h = 1e-5;
    constexpr long long substeps = 50000;
    const glm::vec3 gravity(0.0f, -9.81f, 0.0f);
    State s;
    s.position.resize(1);
    s.position.set(0, glm::dvec3(0.0, 1.6, 0.0));
    s.motion.resize(1);
    s.mass = {1.0f};
    s.inverse_mass = {1.0f};
    s.pinned = {0};
    Vec3Array force;
    force.resize(1);
    start_verlet(s, {glm::dvec3(0.0)}, force, gravity, 0.0, h);
    const Coefficients c = coefficients(0.0, h);
    Rep rep;
    rep.init(s);
    const Inputs in{&force, &s.inverse_mass, &s.pinned, gravity};
    for (long long k = 0; k < substeps; ++k) rep.update(in, c);
    const double t = static_cast<double>(substeps) * h;
    // The simulation's g is the float -9.81f; the exact fall is g t^2 / 2 with that g.
    const double expected = 0.5 * -static_cast<double>(gravity.y) * t * t;
    const double fallen = 1.6 - rep.position(1, 0);
    return std::abs(fallen - expected) / expected;
}

// ---- (3) Speed of the update loop alone. ----
constexpr int kSide = 128;
constexpr int kUpdates = 2000;
constexpr int kRepetitions = 5;

double thread_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct SpeedSetup {
    State state;  // the start: a flat 128 x 128 grid at rest, two corners pinned
    Vec3Array force;
    Coefficients c{};
    glm::vec3 gravity{0.0f, -9.81f, 0.0f};
    double h = 0.0;
    double damping = 0.2;
};

SpeedSetup speed_setup() {
    SpeedSetup su;
    const std::size_t n = static_cast<std::size_t>(kSide) * kSide;
    State& s = su.state;
    s.position.resize(n);
    s.motion.resize(n);
    s.mass.assign(n, 0.5f / static_cast<float>(n));
    s.inverse_mass.assign(n, static_cast<float>(n) / 0.5f);
    s.pinned.assign(n, 0);
    s.pinned[0] = s.pinned[kSide - 1] = 1;
    s.inverse_mass[0] = s.inverse_mass[kSide - 1] = 0.0f;
    su.force.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const int row = static_cast<int>(i) / kSide, col = static_cast<int>(i) % kSide;
        s.position.set(i, glm::dvec3(-0.5 + col / double(kSide - 1), 1.6, -0.5 + row / double(kSide - 1)));
        // A fixed force of the size of the weight (mass 3e-5 kg), different for every particle.
        const double u = static_cast<double>(i);
        su.force.set(i, glm::vec3(static_cast<float>(1e-4 * std::sin(0.37 * u)),
                                  static_cast<float>(2e-4 * std::cos(0.11 * u)),
                                  static_cast<float>(1e-4 * std::sin(0.05 * u + 1.0))));
    }
    su.h = static_cast<double>(kStep) / 544;
    su.c = coefficients(su.damping, su.h);
    return su;
}

// One timed repetition: 2000 updates of a fresh copy of the start.
struct Sample {
    double cpu_ns = 0.0;   // thread CPU time per particle-update
    double wall_ns = 0.0;  // wall time per particle-update
    double checksum = 0.0;
};

struct Timing {
    double cpu_ns = 0.0;   // median over the repetitions
    double wall_ns = 0.0;
};

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

template <class Update>
Sample time_once(std::size_t n, Update&& update) {
    const double c0 = thread_seconds();
    const auto w0 = std::chrono::steady_clock::now();
    for (int k = 0; k < kUpdates; ++k) update();
    const double c1 = thread_seconds();
    const auto w1 = std::chrono::steady_clock::now();
    const double updates = static_cast<double>(kUpdates) * static_cast<double>(n);
    return {(c1 - c0) * 1e9 / updates, std::chrono::duration<double>(w1 - w0).count() * 1e9 / updates, 0.0};
}

template <class Rep>
Sample sample_rep(const SpeedSetup& su) {
    const std::size_t n = su.state.size();
    const Inputs in{&su.force, &su.state.inverse_mass, &su.state.pinned, su.gravity};
    Rep rep;
    rep.init(su.state);
    Sample t = time_once(n, [&] { rep.update(in, su.c); });
    t.checksum = rep.position(1, n / 2);
    return t;
}

// The library's integrate_verlet (D) in the same setting, for comparison with RepD's loop.
Sample sample_library(const SpeedSetup& su) {
    const std::size_t n = su.state.size();
    State s = su.state;
    Sample t = time_once(n, [&] { integrate_verlet(s, su.force, su.gravity, su.damping, su.h); });
    t.checksum = s.position.y[n / 2];
    return t;
}

struct Row {
    std::string name;
    int bytes = 0;
    std::array<double, kSubsteps.size()> error{};
    double free_fall = 0.0;
    Timing speed;
};

template <class Rep>
Row measure(const MassSpring& sim, const std::vector<glm::dvec3>& reference, double size) {
    Row row;
    row.name = Rep::kName;
    row.bytes = Rep::kBytes;
    for (std::size_t k = 0; k < kSubsteps.size(); ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<glm::dvec3> p = run_scene<Rep>(sim, kSubsteps[k]);
        row.error[k] = relative_error(p, reference, size).max;
        std::printf("  %-52s %5d substeps: error %.3e  [%.1f s]\n", row.name.c_str(), kSubsteps[k], row.error[k],
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        std::fflush(stdout);
    }
    row.free_fall = free_fall_error<Rep>();
    std::printf("  %-52s free fall %.3e\n", row.name.c_str(), row.free_fall);
    std::fflush(stdout);
    return row;
}

}  // namespace

int main() {
    const auto start = std::chrono::steady_clock::now();
    const Scene scene = smooth_scene();
    const MassSpring sim = build_simulation(scene);
    const double duration = kSteps * static_cast<double>(kStep);
    const double size = cloth_size(scene);
    std::printf("state-study: hanging %d x %d, ground off, damping %g, %d steps of %.9g s (T = %.9g s), error = "
                "max |x - x_ref| / %g m\n",
                scene.cloth.rows, scene.cloth.cols, static_cast<double>(scene.settings.springs.damping), kSteps,
                static_cast<double>(kStep), duration, size);
    const auto r0 = std::chrono::steady_clock::now();
    const Reference ref = reference_solution(scene, duration, 2e-4, 1e-10, 10);
    std::printf("reference: double RK4 at h = %.3g s after %d halvings; the last halving changed positions by "
                "%.3g of the cloth size (%s 1e-10) [%.1f s]\n",
                ref.substep, ref.halvings, ref.halving_change, ref.converged ? "below" : "NOT below",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count());
    std::fflush(stdout);

    // RepD's loop is the library's update: bit-identical positions.
    bool identical = true;
    for (int substeps : {136, 544}) {
        identical = identical && run_scene<RepD>(sim, substeps) == run_scene_library(sim, substeps);
    }
    std::printf("D's loop against the library's integrate_verlet at 136 and 544 substeps: %s\n",
                identical ? "bit-identical" : "DIFFERENT");

    std::vector<Row> rows;
    rows.push_back(measure<RepA>(sim, ref.positions, size));
    rows.push_back(measure<RepB>(sim, ref.positions, size));
    rows.push_back(measure<RepC<true>>(sim, ref.positions, size));
    rows.push_back(measure<RepD>(sim, ref.positions, size));
    rows.push_back(measure<RepE>(sim, ref.positions, size));
    // C without the fmaf call: the same positions (checked at 136 and 544 substeps), timed apart.
    bool c_same = true;
    for (int substeps : {136, 544}) {
        c_same = c_same && run_scene<RepC<true>>(sim, substeps) == run_scene<RepC<false>>(sim, substeps);
    }
    std::printf("  %s: positions %s C's\n", RepC<false>::kName, c_same ? "bit-identical to" : "DIFFERENT from");

    // Speed: the repetitions go round the representations (A B C D E C' library, A B ...), so that a busy
    // moment of the machine falls on all of them alike; the median of each.
    const SpeedSetup su = speed_setup();
    using Sampler = Sample (*)(const SpeedSetup&);
    const std::array<Sampler, 7> samplers = {sample_rep<RepA>,         sample_rep<RepB>, sample_rep<RepC<true>>,
                                             sample_rep<RepD>,         sample_rep<RepE>, sample_rep<RepC<false>>,
                                             sample_library};
    std::array<std::vector<double>, samplers.size()> cpu, wall;
    double checksum = 0.0;
    for (int r = 0; r < kRepetitions; ++r) {
        for (std::size_t k = 0; k < samplers.size(); ++k) {
            const Sample t = samplers[k](su);
            cpu[k].push_back(t.cpu_ns);
            wall[k].push_back(t.wall_ns);
            checksum += t.checksum;
        }
    }
    std::array<Timing, samplers.size()> speed;
    for (std::size_t k = 0; k < samplers.size(); ++k) speed[k] = {median(cpu[k]), median(wall[k])};
    for (std::size_t k = 0; k < rows.size(); ++k) rows[k].speed = speed[k];
    const std::array<std::string, samplers.size()> names = {rows[0].name, rows[1].name, rows[2].name, rows[3].name,
                                                            rows[4].name, RepC<false>::kName,
                                                            "library integrate_verlet (D, particle-major, glm)"};
    for (std::size_t k = 0; k < samplers.size(); ++k) {
        std::printf("  %-58s update %6.3f ns (CPU) %6.3f ns (wall) per particle-update\n", names[k].c_str(),
                    speed[k].cpu_ns, speed[k].wall_ns);
    }
    const Timing c_no_call = speed[5];

    std::printf("\n| representation | bytes per particle of state | error at 136 | error at 544 | error at 4096 | "
                "free-fall relative error | ns per particle-update |\n|---|---:|---:|---:|---:|---:|---:|\n");
    for (const Row& r : rows) {
        std::printf("| %s | %d | %.2e | %.2e | %.2e | %.2e | %.2f |\n", r.name.c_str(), r.bytes, r.error[0],
                    r.error[1], r.error[2], r.free_fall, r.speed.cpu_ns);
    }
    std::printf("\nError: max over particles |x - x_ref| / 1 m after 15 steps of float(1/60) s (hanging 32 x 32, "
                "ground off) at 136, 544, 4096 substeps per step, against double RK4 at h = %.3g s (halving change "
                "%.2e). Free fall: 0.5 s at h = 1e-5 s from 1.6 m, no damping, against g t^2/2 with g = -9.81f. "
                "Speed: the update loop alone, 128 x 128 particles, 2000 updates, median of 5 repetitions taken in turn (thread CPU time); "
                "bytes: position + motion (masses and pins, common to all, not counted).\n",
                ref.substep, ref.halving_change);
    std::printf("C's time includes a call to libm's fmaf per product (the project builds without -mfma); C' (the "
                "same bits from an exact double product, no call) takes %.2f ns.\n",
                c_no_call.cpu_ns);
    const Row& d = rows[3];
    const Row& e = rows[4];
    std::printf("E vs D: error %.2fx, %.2fx, %.2fx of D's at 136, 544, 4096 substeps; free fall %.2e vs %.2e; "
                "update %.2fx D's time.\n",
                e.error[0] / d.error[0], e.error[1] / d.error[1], e.error[2] / d.error[2], e.free_fall, d.free_fall,
                e.speed.cpu_ns / d.speed.cpu_ns);
    std::printf("(checksum %.6g) [total %.1f s]\n", checksum,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return identical && c_same ? 0 : 1;
}
