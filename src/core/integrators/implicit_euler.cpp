#include "integrators/integrators.hpp"
#include "integrators/integrator_step.hpp"

#include "model/forces.hpp"
#include "model/membrane.hpp"

#include <glm/geometric.hpp>

#include <cmath>

namespace clothsim {
namespace {

// out = K u for the spring Jacobian K = dF/dx at `position`. Per spring, with n = d/|d| and
// alpha = max(0, 1 - L0/|d|): Ks = k (n n^T + alpha (I - n n^T)); K adds Ks (u_b - u_a) on a, minus on b.
// Clamping alpha at 0 drops the destabilising transverse term of compressed springs (Baraff & Witkin
// 1998, section 5.2; Choi & Ko 2002), keeping -K positive semi-definite.
void spring_jacobian_times(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                           const Vec3Array& u, Vec3Array& out) {
    out.resize(u.size());
    for (const Spring& s : topology.springs) {
        const float k = stiffness_of(springs, s);
        if (k == 0.0f) continue;
        const glm::vec3 d(position.get(s.b) - position.get(s.a));
        const float length = glm::length(d);
        const glm::vec3 du = u.get(s.b) - u.get(s.a);
        glm::vec3 f;
        if (s.rest_length == 0.0f) {
            f = k * du;  // F = k d exactly: K = k I
        } else {
            if (!(length > 1e-12f)) continue;
            const glm::vec3 n = d / length;
            const SpringCurve& curve = curve_of(springs, s);
            const glm::vec3 along = glm::dot(n, du) * n;
            if (curve.knots == 0) {
                const float alpha = std::max(0.0f, 1.0f - s.rest_length / length);
                f = k * (along + alpha * (du - along));
            } else {
                // A curved spring (stretch_curve.hpp): along d its tangent k t'(e), across it k t(e) / |d|.
                const float e = length - s.rest_length;
                const float tangent = static_cast<float>(curve.tangent(double(e) / double(s.rest_length)));
                const float alpha = std::max(0.0f, curve.stretch_term(e, s.rest_length) / length);
                f = k * (tangent * along + alpha * (du - along));
            }
        }
        out.add(s.a, f);
        out.add(s.b, -f);
    }
    // Bends are linear: K u = -k w (u_a - 2 u_m + u_b) on a and b, twice that with the sign flipped on m.
    for (const Bend& b : topology.bends) {
        const float k = stiffness_of(springs, b);
        if (k == 0.0f) continue;
        const glm::vec3 e = k * ((u.get(b.a) - u.get(b.m)) + (u.get(b.b) - u.get(b.m)));
        out.add(b.a, -e);
        out.add(b.m, 2.0f * e);
        out.add(b.b, -e);
    }
    // Hinges are linear too: K u = -k c_i (sum_j c_j u_j) on v_i.
    for (const Hinge& h : topology.hinges) {
        const float k = stiffness_of(springs, h);
        if (k == 0.0f) continue;
        glm::vec3 sum(0.0f);
        for (int i = 0; i < 4; ++i) sum += h.c[i] * u.get(h.v[i]);
        const glm::vec3 e = k * sum;
        for (int i = 0; i < 4; ++i) out.add(h.v[i], -h.c[i] * e);
    }
    // Membrane triangles (membrane.hpp), in double: with dw = sum_i b_i u_i, the strains change by
    // de_u = n_u . dw_u, de_v = n_v . dw_v, dgamma = w_v . dw_u + w_u . dw_v, the stresses by the tensor (a curve's
    // tangent on its direction), and K u on corner i is bu_i dp_u + bv_i dp_v with
    // dp_u = -A (dsigma_u n_u + max(sigma_u, 0) (I - n_u n_u^T) dw_u / |w_u| + dtau w_v), dp_v likewise. The
    // stretch's transverse term is dropped under compression and the shear's tau (bu bv^T + bv bu^T) always, as
    // the compressed springs' above: -K stays positive semi-definite.
    if (topology.membranes.empty()) return;
    const MembraneTensor c = membrane_tensor(springs);
    for (const Membrane& m : topology.membranes) {
        const MembraneStrain s = membrane_strain(position, m, c, springs);
        if (!s.valid) continue;
        glm::dvec3 du(0.0), dv(0.0);
        for (int i = 0; i < 3; ++i) {
            du += double(m.bu[i]) * glm::dvec3(u.get(m.v[i]));
            dv += double(m.bv[i]) * glm::dvec3(u.get(m.v[i]));
        }
        const glm::dvec3 nu = s.wu / s.lu, nv = s.wv / s.lv;
        const double deu = glm::dot(nu, du), dev = glm::dot(nv, dv);
        const double dsu = c.c11 * springs.membrane_curve[0].tangent(s.eu) * deu + c.c12 * dev;
        const double dsv = c.c22 * springs.membrane_curve[1].tangent(s.ev) * dev + c.c12 * deu;
        const double dtau = c.c66 * (glm::dot(s.wv, du) + glm::dot(s.wu, dv));
        const double a = -double(m.area);
        const glm::dvec3 pu = a * (dsu * nu + (std::max(s.sigma_u, 0.0) / s.lu) * (du - deu * nu) + dtau * s.wv);
        const glm::dvec3 pv = a * (dsv * nv + (std::max(s.sigma_v, 0.0) / s.lv) * (dv - dev * nv) + dtau * s.wu);
        for (int i = 0; i < 3; ++i) out.add(m.v[i], glm::vec3(double(m.bu[i]) * pu + double(m.bv[i]) * pv));
    }
}

double dot(const Vec3Array& a, const Vec3Array& b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        sum += double(a.x[i]) * b.x[i] + double(a.y[i]) * b.y[i] + double(a.z[i]) * b.z[i];
    }
    return sum;
}

}  // namespace

LinearSolve step_implicit_euler(State& state, const Dynamics& dynamics, const Topology& topology,
                        const SpringSettings& springs, float tolerance, double substep) {
    const std::size_t n = state.size();
    const float c = dynamics.damping;
    const float h = static_cast<float>(substep);  // the solve's arithmetic
    state.substep = substep;
    Vec3Array force, v, kv;
    force.resize(n);
    dynamics.forces(state, force);
    v.resize(n);
    for (std::size_t i = 0; i < n; ++i) v.set(i, glm::vec3(state.motion.get(i) / substep));
    spring_jacobian_times(topology, state.position, springs, v, kv);

    // b = h (F + M g - c M v + h K v); pinned rows are zero (their dv is held at 0).
    Vec3Array b;
    b.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) continue;
        const float m = state.mass[i];
        b.set(i, h * (force.get(i) + m * dynamics.gravity - c * m * v.get(i) + h * kv.get(i)));
    }
    // A u = (1 + h c) M u - h^2 K u, with pinned rows and columns filtered out.
    auto apply = [&](const Vec3Array& u, Vec3Array& out) {
        Vec3Array ku;
        spring_jacobian_times(topology, state.position, springs, u, ku);
        out.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            if (state.pinned[i]) continue;
            out.set(i, (1.0f + h * c) * state.mass[i] * u.get(i) - (h * h) * ku.get(i));
        }
    };

    // Conjugate gradients from dv = 0.
    Vec3Array dv, r = b, p = b, ap;
    dv.resize(n);
    const double b_norm2 = dot(b, b);
    double r2 = b_norm2;
    const double stop2 = double(tolerance) * double(tolerance) * b_norm2;
    int iterations = 0;
    const int max_iterations = 2000;
    while (r2 > stop2 && r2 > 0.0 && iterations < max_iterations) {
        apply(p, ap);
        const double pap = dot(p, ap);
        if (!(pap > 0.0)) break;  // not positive definite along p: stop with what we have
        const float alpha = static_cast<float>(r2 / pap);
        for (std::size_t i = 0; i < n; ++i) {
            dv.add(i, alpha * p.get(i));
            r.add(i, -alpha * ap.get(i));
        }
        const double r2_new = dot(r, r);
        const float beta = static_cast<float>(r2_new / r2);
        for (std::size_t i = 0; i < n; ++i) p.set(i, r.get(i) + beta * p.get(i));
        r2 = r2_new;
        ++iterations;
    }

    // v' h = v h + dv h, in double: the velocity change is small next to the velocity at small substeps.
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) {
            state.motion.set(i, glm::dvec3(0.0));
            continue;
        }
        const glm::dvec3 moved = state.motion.get(i) + glm::dvec3(dv.get(i)) * substep;
        state.motion.set(i, moved);
        state.position.add(i, moved);
    }
    return {iterations, b_norm2 > 0.0 ? std::sqrt(r2 / b_norm2) : 0.0};
}

void implicit_euler_substep(IntegratorContext& c) {
    c.solve = step_implicit_euler(c.state, c.dynamics, c.topology, c.settings.springs, c.settings.integration.tolerance, c.h);
}

}  // namespace clothsim
