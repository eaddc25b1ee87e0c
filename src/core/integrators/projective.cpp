#include "integrators/projective.hpp"
#include "integrators/integrator_step.hpp"

#include "model/forces.hpp"
#include "model/gaussian_curvature.hpp"
#include "model/membrane.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <glm/geometric.hpp>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace clothsim {

using Positions = Eigen::Matrix<double, Eigen::Dynamic, 3>;  // one row per free particle

// The global step's matrix over the free particles, factorised, and what the step needs to use it.
struct ProjectiveSolver::Factor {
    double h_hat = 0.0;
    float damping = 0.0f;
    std::vector<int> free_index;        // per particle: its row, or -1 when pinned or absent
    std::vector<std::uint32_t> particle;  // per row: the particle
    Eigen::VectorXd inertia;            // per row: m' / h'^2
    Eigen::SparseMatrix<double> matrix;  // M'/h'^2 + L over the free rows and columns
    struct Coupling {
        int row;
        std::uint32_t pinned;
        double value;
    };
    std::vector<Coupling> coupling;  // L's entries between a free row and a pinned column
    // P A P^T = L D L^T (Eigen's SimplicialLDLT with an AMD ordering), copied out so that a solve walks L once
    // for x, y and z together, each pass as gathers: L's strict lower part by rows (the forward pass) and by
    // columns (the backward pass, rows of L^T), D, and P as "row r goes to order[r]". L is kept in float: the
    // solve only applies L-BFGS's initial inverse Hessian, whose rounding changes the search direction, never
    // the gradient or the energy the iterations are judged by (both in double).
    struct Triangle {
        std::vector<int> start;  // per row (or column) and one past the end
        std::vector<int> index;  // column (or row) of each entry
        std::vector<float> value;
    };
    Triangle by_row, by_column;
    std::vector<double> diagonal;
    std::vector<int> order;

    // Solves A x = b for the three columns at once (rows of three, in place).
    void solve(Positions& b) const;
};

void ProjectiveSolver::Factor::solve(Positions& b) const {
    const int n = static_cast<int>(order.size());
    std::vector<double> z(3 * static_cast<std::size_t>(n));
    for (int r = 0; r < n; ++r) {
        double* zr = &z[3 * static_cast<std::size_t>(order[r])];
        zr[0] = b(r, 0);
        zr[1] = b(r, 1);
        zr[2] = b(r, 2);
    }
    auto gather = [&](const Triangle& t, int j) {  // z_j -= sum over the entries of row (column) j
        double s0 = z[3 * j], s1 = z[3 * j + 1], s2 = z[3 * j + 2];
        for (int p = t.start[j]; p < t.start[j + 1]; ++p) {
            const double* zi = &z[3 * static_cast<std::size_t>(t.index[p])];
            const double v = t.value[p];
            s0 -= v * zi[0];
            s1 -= v * zi[1];
            s2 -= v * zi[2];
        }
        z[3 * j] = s0;
        z[3 * j + 1] = s1;
        z[3 * j + 2] = s2;
    };
    for (int j = 0; j < n; ++j) gather(by_row, j);  // L z' = z
    for (int j = 0; j < n; ++j) {
        const double d = 1.0 / diagonal[j];
        z[3 * j] *= d;
        z[3 * j + 1] *= d;
        z[3 * j + 2] *= d;
    }
    for (int j = n - 1; j >= 0; --j) gather(by_column, j);  // L^T x = z'
    for (int r = 0; r < n; ++r) {
        const double* zr = &z[3 * static_cast<std::size_t>(order[r])];
        b(r, 0) = zr[0];
        b(r, 1) = zr[1];
        b(r, 2) = zr[2];
    }
}

namespace {

std::shared_ptr<const ProjectiveSolver::Factor> factorise(const State& state, const Topology& topology,
                                                          const SpringSettings& springs, double h_hat,
                                                          float damping) {
    auto f = std::make_shared<ProjectiveSolver::Factor>();
    f->h_hat = h_hat;
    f->damping = damping;
    const std::size_t n = state.size();
    f->free_index.assign(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) continue;
        f->free_index[i] = static_cast<int>(f->particle.size());
        f->particle.push_back(static_cast<std::uint32_t>(i));
    }
    const int rows = static_cast<int>(f->particle.size());
    const double inertia_scale = (1.0 + h_hat * damping) / (h_hat * h_hat);
    f->inertia.resize(rows);
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(rows + 4 * topology.springs.size() + 9 * topology.bends.size() + 16 * topology.hinges.size() +
                    9 * topology.membranes.size());
    for (int r = 0; r < rows; ++r) {
        f->inertia[r] = inertia_scale * state.mass[f->particle[r]];
        entries.emplace_back(r, r, f->inertia[r]);
    }
    auto add = [&](std::uint32_t i, std::uint32_t j, double value) {
        const int r = f->free_index[i];
        if (r < 0) return;
        const int c = f->free_index[j];
        if (c >= 0) {
            entries.emplace_back(r, c, value);
        } else {
            f->coupling.push_back({r, j, value});
        }
    };
    for (const Spring& s : topology.springs) {
        const double k = stiffness_of(springs, s);
        if (k == 0.0) continue;
        add(s.a, s.a, k);
        add(s.b, s.b, k);
        add(s.a, s.b, -k);
        add(s.b, s.a, -k);
    }
    // A soft clip's hold, 0.5 k |x - anchor|^2, adds k on its particle's diagonal (and k anchor to the
    // right-hand side): quadratic, so A holds it exactly and the step takes it implicitly.
    for (const SoftClipSpring& hold : topology.clip_springs) add(hold.particle, hold.particle, hold.stiffness);
    // A bend's energy 0.5 k |x_a - 2 x_m + x_b|^2 adds k b b^T with b = (1, -2, 1) on (a, m, b).
    for (const Bend& b : topology.bends) {
        const double k = stiffness_of(springs, b);
        if (k == 0.0) continue;
        const std::uint32_t p[3] = {b.a, b.m, b.b};
        const double w[3] = {1.0, -2.0, 1.0};
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) add(p[i], p[j], k * w[i] * w[j]);
        }
    }
    // A hinge's energy 0.5 k |sum_i c_i x_i|^2 adds k c c^T on its four particles; quadratic like a bend.
    for (const Hinge& h : topology.hinges) {
        const double k = stiffness_of(springs, h);
        if (k == 0.0) continue;
        for (int i = 0; i < 4; ++i) {
            for (int j = 0; j < 4; ++j) add(h.v[i], h.v[j], k * double(h.c[i]) * double(h.c[j]));
        }
    }
    // A membrane triangle (membrane.hpp) is not quadratic: the matrix takes A (C11 bu bu^T + C22 bv bv^T), its
    // stretch's stiffness at rest, as a spring's k; the local step's right-hand side then gives the true
    // gradient (below), and the quasi-Newton iterations add what the matrix misses (its shear).
    if (!topology.membranes.empty()) {
        const MembraneTensor c = membrane_tensor(springs);
        for (const Membrane& m : topology.membranes) {
            const double ku = double(m.area) * c.c11, kv = double(m.area) * c.c22;
            for (int i = 0; i < 3; ++i) {
                for (int j = 0; j < 3; ++j) {
                    add(m.v[i], m.v[j], ku * double(m.bu[i]) * double(m.bu[j]) + kv * double(m.bv[i]) * double(m.bv[j]));
                }
            }
        }
    }
    f->matrix.resize(rows, rows);
    f->matrix.setFromTriplets(entries.begin(), entries.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> cholesky;
    cholesky.compute(f->matrix); 
    if (cholesky.info() != Eigen::Success) {
        // M'/h'^2 > 0 on the diagonal and L positive semi-definite: only a NaN in the settings gets here.
        throw std::runtime_error("projective: the global matrix could not be factorised (non-finite stiffness?)");
    }
    const Eigen::SparseMatrix<double>& lower = cholesky.matrixL().nestedExpression();
    Eigen::SparseMatrix<float> strict = lower.triangularView<Eigen::StrictlyLower>().cast<float>();
    Eigen::SparseMatrix<float, Eigen::RowMajor> strict_rows = strict;
    strict.makeCompressed();
    strict_rows.makeCompressed();
    auto copy = [](const auto& m, ProjectiveSolver::Factor::Triangle& t) {
        const int outer = static_cast<int>(m.outerSize());
        t.start.assign(m.outerIndexPtr(), m.outerIndexPtr() + outer + 1);
        t.index.assign(m.innerIndexPtr(), m.innerIndexPtr() + m.nonZeros());
        t.value.assign(m.valuePtr(), m.valuePtr() + m.nonZeros());
    };
    copy(strict, f->by_column);
    copy(strict_rows, f->by_row);
    const Eigen::VectorXd d = cholesky.vectorD();  // a copy: vectorD() returns by value
    f->diagonal.assign(d.data(), d.data() + rows);
    const Eigen::VectorXi p = cholesky.permutationP().indices();
    f->order.assign(p.data(), p.data() + rows);
    return f;
}

}  // namespace

LinearSolve ProjectiveSolver::step(State& state, const Topology& topology, const SpringSettings& springs,
                                   const Inputs& inputs, double h, bool continues) {
    const std::size_t n = state.size();
    const double h_hat = 2.0 * h / 3.0;
    const double c = inputs.damping;
    if (!factor_ || factor_->h_hat != h_hat || factor_->damping != inputs.damping ||
        factor_->free_index.size() != n) {
        factor_ = factorise(state, topology, springs, h_hat, inputs.damping);
    }
    const Factor& f = *factor_;
    const glm::dvec3 g(inputs.gravity);
    auto external = [&](std::size_t i) {
        return inputs.external ? glm::dvec3(inputs.external->get(i)) : glm::dvec3(0.0);
    };

    // BDF2's history. Without one, x_{n-1} and v_{n-1} come from a Taylor step back with the current
    // acceleration: errors O(h^3) and O(h^2), as a second-order start needs.
    DVec3Array velocity;
    velocity.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        if (!state.pinned[i]) velocity.set(i, state.motion.get(i) / h);
    }
    if (!continues || previous_position_.size() != n) {
        DVec3Array force;
        force.resize(n);
        accumulate_spring_forces(topology, state.position, springs, force);
        accumulate_soft_clip_forces(topology, state.position, force);
        previous_position_ = state.position;
        previous_velocity_.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            if (state.pinned[i]) continue;
            const glm::dvec3 v = velocity.get(i);
            const glm::dvec3 a = (force.get(i) + external(i)) / double(state.mass[i]) + g - c * v;
            previous_position_.set(i, state.position.get(i) - h * v + (0.5 * h * h) * a);
            previous_velocity_.set(i, v - h * a);
        }
    }

    // y = x^ + h' (v^ + h' (g + f_ext / m)) / (1 + h' c), with x^ = (4 x_n - x_{n-1}) / 3 and v^ likewise.
    const int rows = static_cast<int>(f.particle.size());
    // The iterations start from the predictor x^ + h' v^ / (1 + h' c), y without the loads: a cloth at rest
    // starts at its equilibrium, where starting from y would leave the loads' h'^2 (g + f/m) to iterations
    // that cannot remove all of it (a sag that never settles).
    Positions x_hat(rows, 3), target(rows, 3), x(rows, 3);
    double load = 0.0;  // |M' (g + f_ext / m)|^2: the scale the residual is measured against
    for (int r = 0; r < rows; ++r) {
        const std::uint32_t i = f.particle[r];
        const glm::dvec3 xh = (4.0 * state.position.get(i) - previous_position_.get(i)) / 3.0;
        const glm::dvec3 vh = (4.0 * velocity.get(i) - previous_velocity_.get(i)) / 3.0;
        const glm::dvec3 a = g + external(i) / double(state.mass[i]);
        const glm::dvec3 start = xh + h_hat * vh / (1.0 + h_hat * c);
        const glm::dvec3 y = start + (h_hat * h_hat / (1.0 + h_hat * c)) * a;
        x_hat.row(r) << xh.x, xh.y, xh.z;
        target.row(r) << y.x, y.y, y.z;
        x.row(r) << start.x, start.y, start.z;
        const double m = (1.0 + h_hat * c) * state.mass[i];
        load += m * m * glm::dot(a, a);
    }
    // This step's start becomes the next step's history.
    previous_position_ = state.position;
    previous_velocity_ = std::move(velocity);

    // The right-hand side's constant part: M'/h'^2 y minus the pinned particles' share of L x.
    Positions constant = f.inertia.asDiagonal() * target;
    for (const Factor::Coupling& e : f.coupling) {
        const glm::dvec3 p = state.position.get(e.pinned);
        constant.row(e.row) -= e.value * Eigen::RowVector3d(p.x, p.y, p.z);
    }
    for (const SoftClipSpring& hold : topology.clip_springs) {
        const int r = f.free_index[hold.particle];
        if (r >= 0) constant.row(r) += double(hold.stiffness) * Eigen::RowVector3d(hold.anchor.x, hold.anchor.y, hold.anchor.z);
    }

    // The positions every local step reads: the pinned ones from the state, the free ones from x.
    DVec3Array& position = state.position;
    auto write = [&](const Positions& at) {
        for (int r = 0; r < rows; ++r) position.set(f.particle[r], glm::dvec3(at(r, 0), at(r, 1), at(r, 2)));
    };
    // At the positions last written (x for the free particles): g(x), returned, and the local step's
    // right-hand side b(x) in `rhs`, in one pass over the springs. The local step gives each spring its target
    // d_s = L0 (x_b - x_a)/|x_b - x_a| and adds k d_s on b, -k d_s on a; then grad g(x) = A x - b(x).
    Positions rhs(rows, 3);
    auto evaluate = [&](const Positions& at) {
        rhs = constant;
        double e = 0.5 * (f.inertia.asDiagonal() * (at - target)).cwiseProduct(at - target).sum();
        for (const Spring& s : topology.springs) {
            const double k = stiffness_of(springs, s);
            if (k == 0.0) continue;
            const glm::dvec3 d = position.get(s.b) - position.get(s.a);
            const double length = glm::length(d);
            const double stretch = length - s.rest_length;
            const SpringCurve& curve = curve_of(springs, s);
            e += spring_energy(k, curve, stretch, s.rest_length);
            if (s.rest_length == 0.0f || !(length > 1e-12)) continue;
            // A curved spring's target length is |d| - t(|d| - L0) instead of L0, so that k (d - d_s) is its
            // force: the constant matrix with the true gradient (Liu, Bouaziz & Kavan 2017, "Quasi-Newton methods
            // for real-time simulation of hyperelastic materials").
            const double target_length =
                curve.knots == 0 ? double(s.rest_length) : length - curve.stretch_term(stretch, double(s.rest_length));
            const glm::dvec3 kd = d * (k * target_length / length);
            const int ra = f.free_index[s.a], rb = f.free_index[s.b];
            if (ra >= 0) rhs.row(ra) -= Eigen::RowVector3d(kd.x, kd.y, kd.z);
            if (rb >= 0) rhs.row(rb) += Eigen::RowVector3d(kd.x, kd.y, kd.z);
        }
        for (const Bend& b : topology.bends) {
            const glm::dvec3 d = bend_difference(position, b);
            e += 0.5 * double(stiffness_of(springs, b)) * glm::dot(d, d);
        }
        for (const Hinge& hinge : topology.hinges) {
            const glm::dvec3 d = hinge_difference(position, hinge);
            e += 0.5 * double(stiffness_of(springs, hinge)) * glm::dot(d, d);
        }
        // A membrane's share of b(x): its matrix entries times x plus its forces, so that A x - b(x) is minus its
        // force (A's bu bu^T x on corner i is bu_i w_u).
        if (!topology.membranes.empty()) {
            const MembraneTensor tensor = membrane_tensor(springs);
            for (const Membrane& m : topology.membranes) {
                const MembraneStrain s = membrane_strain(position, m, tensor, springs);  // once: energy, force, b
                e += membrane_energy(s, double(m.area), tensor, springs);
                glm::dvec3 pu(0.0), pv(0.0);
                if (s.valid) membrane_forces(s, double(m.area), pu, pv);
                const glm::dvec3 qu = double(m.area) * tensor.c11 * s.wu + pu;
                const glm::dvec3 qv = double(m.area) * tensor.c22 * s.wv + pv;
                for (int i = 0; i < 3; ++i) {
                    const int r = f.free_index[m.v[i]];
                    if (r < 0) continue;
                    const glm::dvec3 b = double(m.bu[i]) * qu + double(m.bv[i]) * qv;
                    rhs.row(r) += Eigen::RowVector3d(b.x, b.y, b.z);
                }
            }
        }
        // The Gaussian-curvature term's (gaussian_curvature.hpp): none of it in A, all its force in b(x).
        if (has_gaussian_term(topology, springs)) {
            e += gaussian_energy(topology, position, springs);
            visit_gaussian_forces(topology, position, springs, [&](std::uint32_t i, const glm::dvec3& force) {
                const int r = f.free_index[i];
                if (r >= 0) rhs.row(r) += Eigen::RowVector3d(force.x, force.y, force.z);
            });
        }
        for (const SoftClipSpring& hold : topology.clip_springs) {
            const glm::dvec3 d = position.get(hold.particle) - hold.anchor;
            e += 0.5 * double(hold.stiffness) * glm::dot(d, d);
        }
        return e;
    };
    auto dot = [](const Positions& a, const Positions& b) { return a.cwiseProduct(b).sum(); };

    // Quasi-Newton (Liu, Bouaziz & Kavan 2017, "Quasi-Newton methods for real-time simulation of hyperelastic
    // materials"): L-BFGS with the global matrix as its initial Hessian, so its first iteration is exactly a
    // local-global step, and later ones add the curvature the constant matrix misses (a spring's transverse
    // stiffness, k (1 - L0/|d|), is nearly 0 at rest, while the matrix gives it k: plain local-global
    // iterations crawl on the swinging and rotating modes of stiff cloth). A backtracking line search keeps every
    // iteration lowering g. grad g(x) = A x - b(x), b the right-hand side of the local step at x.
    constexpr int kMemory = 5;
    std::vector<Positions> s_history, y_history;
    std::vector<double> rho;
    write(x);
    double energy = evaluate(x);
    Positions gradient = f.matrix * x - rhs;
    const double first = std::max(gradient.norm(), std::sqrt(load));
    double residual = gradient.norm();
    int iterations = 0;
    while (iterations < inputs.iterations && residual > double(inputs.tolerance) * first) {
        // The two-loop recursion: direction = -H grad, H0 = A^-1.
        Positions q = gradient;
        const int m = static_cast<int>(s_history.size());
        std::vector<double> alpha(m);
        for (int i = m - 1; i >= 0; --i) {
            alpha[i] = rho[i] * dot(s_history[i], q);
            q -= alpha[i] * y_history[i];
        }
        f.solve(q);
        for (int i = 0; i < m; ++i) {
            const double beta = rho[i] * dot(y_history[i], q);
            q += (alpha[i] - beta) * s_history[i];
        }
        Positions direction = -q;
        double slope = dot(gradient, direction);
        if (!(slope < 0.0)) {  // not a descent direction: forget the curvature pairs, take the plain step
            s_history.clear();
            y_history.clear();
            rho.clear();
            direction = -gradient;
            f.solve(direction);
            slope = dot(gradient, direction);
            if (!(slope < 0.0)) break;
        }
        // A step is accepted by Armijo's sufficient decrease, or, where g's change is within its round-off, by
        // the approximate Wolfe conditions of Hager & Zhang (2005, "A new conjugate gradient method with
        // guaranteed descent and an efficient line search", SIAM J. Optim. 16(1), eq. 4.1): the slope along
        // the direction has fallen to between sigma and 2 delta - 1 of its start. At small substeps g is the
        // inertia's M'/h'^2 |x - y|^2 plus the springs' whole energy, and an iteration's decrease falls below
        // g's round-off long before the gradient is small: Armijo alone then rejects every step and the
        // iterations stop with the residual where it is.
        constexpr double kArmijo = 1e-4, kDelta = 0.1, kSigma = 0.9;
        const double round_off = 1e-12 * std::abs(energy);
        double step = 1.0;
        Positions next, next_gradient;
        double next_energy = energy;
        bool accepted = false;
        for (int halving = 0; halving < 20 && !accepted; ++halving, step *= 0.5) {
            next = x + step * direction;
            write(next);
            next_energy = evaluate(next);
            if (next_energy <= energy + kArmijo * step * slope) {
                next_gradient = f.matrix * next - rhs;
                accepted = true;
            } else if (next_energy <= energy + round_off) {
                next_gradient = f.matrix * next - rhs;
                const double next_slope = dot(next_gradient, direction);
                accepted = kSigma * slope <= next_slope && next_slope <= (2.0 * kDelta - 1.0) * slope;
            }
        }
        if (!accepted && next_energy <= energy) {  // the shortest step still lowers g: taken
            next_gradient = f.matrix * next - rhs;
            accepted = true;
        }
        if (!accepted) {  // no decrease left along the direction: converged to round-off
            write(x);
            break;
        }
        Positions s_k = next - x, y_k = next_gradient - gradient;
        const double sy = dot(s_k, y_k);
        if (sy > 1e-300) {
            if (static_cast<int>(s_history.size()) == kMemory) {
                s_history.erase(s_history.begin());
                y_history.erase(y_history.begin());
                rho.erase(rho.begin());
            }
            s_history.push_back(std::move(s_k));
            y_history.push_back(std::move(y_k));
            rho.push_back(1.0 / sy);
        }
        x = std::move(next);
        gradient = std::move(next_gradient);
        energy = next_energy;
        residual = gradient.norm();
        ++iterations;
    }

    // v_{n+1} = (x_{n+1} - x^) / h'; motion keeps v h.
    for (int r = 0; r < rows; ++r) {
        const glm::dvec3 v((x(r, 0) - x_hat(r, 0)) / h_hat, (x(r, 1) - x_hat(r, 1)) / h_hat,
                           (x(r, 2) - x_hat(r, 2)) / h_hat);
        state.motion.set(f.particle[r], v * h);
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) state.motion.set(i, glm::dvec3(0.0));
    }
    state.substep = h;
    return {iterations, first > 0.0 ? residual / first : 0.0};
}

// Wind, contact and a grab are held at their value at the start of the substep; soft clips' holds are
// quadratic and in the solver's matrix (projective.hpp): held fixed over a BDF2 step they would feed it energy.
void projective_substep(IntegratorContext& c) {
    Vec3Array external;
    c.frozen_external(external);
    ProjectiveSolver::Inputs inputs;
    inputs.external = &external;
    inputs.gravity = c.settings.forces.gravity;
    inputs.damping = c.dynamics.damping;
    inputs.iterations = c.settings.integration.iterations;
    inputs.tolerance = c.settings.integration.tolerance;
    c.solve = c.caches.projective.step(c.state, c.topology, c.settings.springs, inputs, c.h, c.continues);
}

}  // namespace clothsim
