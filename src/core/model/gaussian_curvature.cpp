#include "model/gaussian_curvature.hpp"

#include "integrators/fast_solver.hpp"

#include <glm/geometric.hpp>

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace clothsim {

namespace {

double corner_angle(const glm::dvec3& e1, const glm::dvec3& e2) {
    return std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2));
}

}  // namespace

std::optional<HingeResponse> hinge_response(const std::vector<glm::dvec3>& rest, const Hinge& h, glm::dvec3 u_axis) {
    const glm::dvec3 x0 = rest[h.v[0]];
    const glm::dvec3 edge = rest[h.v[1]] - x0;
    const glm::dvec3 n0 = glm::cross(edge, rest[h.v[2]] - x0), n1 = glm::cross(rest[h.v[3]] - x0, edge);
    const double a0 = 0.5 * glm::length(n0), a1 = 0.5 * glm::length(n1);
    if (!(a0 > 0.0) || !(a1 > 0.0)) return std::nullopt;
    const glm::dvec3 n = n0 / (2.0 * a0);
    glm::dvec3 u = u_axis - glm::dot(u_axis, n) * n;
    if (!(glm::length(u) > 1e-9 * glm::length(u_axis))) return std::nullopt;
    u = glm::normalize(u);
    const glm::dvec3 v = glm::cross(n, u);
    HingeResponse r;
    // The rest dihedral angle's sine, |n0 x n1| / (|n0| |n1|).
    r.flat = glm::length(glm::cross(n0, n1)) <= 1e-6 * 4.0 * a0 * a1;
    r.area = a0 + a1;
    // With the hinge's own (float) cotangent weights, as its energy uses them.
    for (int i = 0; i < 4; ++i) {
        const glm::dvec3 p = rest[h.v[i]] - x0;
        const double pu = glm::dot(p, u), pv = glm::dot(p, v);
        r.alpha += 0.5 * double(h.c[i]) * pu * pu;
        r.beta += 0.5 * double(h.c[i]) * pv * pv;
    }
    return r;
}

GaussianCurvature gaussian_curvature(const std::vector<glm::dvec3>& rest,
                                     const std::vector<std::array<std::uint32_t, 3>>& triangles,
                                     const std::vector<Hinge>& hinges, glm::dvec3 u_axis) {
    GaussianCurvature term;
    double cross_u = 0.0, cross_v = 0.0, area = 0.0;
    for (const Hinge& h : hinges) {
        const std::optional<HingeResponse> r = hinge_response(rest, h, u_axis);
        if (!r) continue;
        if (!r->flat) return term;  // a bent hinge's term would pull at rest
        cross_u += double(h.weight_u) * r->alpha * r->beta;
        cross_v += double(h.weight_v) * r->alpha * r->beta;
    }
    glm::dvec3 normal(0.0);
    for (const auto& t : triangles) {
        const glm::dvec3 n = glm::cross(rest[t[1]] - rest[t[0]], rest[t[2]] - rest[t[0]]);
        area += 0.5 * glm::length(n);
        normal += n;
    }
    if (!(area > 0.0) || !(glm::length(normal) > 0.0)) return term;
    find_rim(term, triangles, rest.size());
    // The hinges couple the curvatures over the whole area, the angle defects measure K at the interior vertices
    // only (a rim strip of about half a spacing is left out): the term's weight is the hinges' coupling over the
    // area whose K the defects measure, so that a uniform curvature's coupling cancels. That area is the
    // defects' sum over K for the rest shape lifted to z = 0.5 kappa (x^2 + y^2) off its plane (K = kappa^2).
    const glm::dvec3 n = glm::normalize(normal);
    const glm::dvec3 e1 = glm::normalize(std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1.0, 0.0, 0.0)) : glm::cross(n, glm::dvec3(0.0, 1.0, 0.0)));
    const glm::dvec3 e2 = glm::cross(n, e1);
    double size = 0.0;
    for (const glm::dvec3& p : rest) size = std::max(size, glm::length(p - rest[0]));
    const double kappa = 1e-3 / std::max(size, 1e-12);  // slopes of 1e-3: K within 1e-6 of kappa^2
    DVec3Array lifted;
    lifted.resize(rest.size());
    for (std::size_t i = 0; i < rest.size(); ++i) {
        const glm::dvec3 q = rest[i] - rest[0];
        const double x = glm::dot(q, e1), y = glm::dot(q, e2);
        lifted.set(i, rest[i] + n * (0.5 * kappa * (x * x + y * y)));
    }
    double angles = 0.0;
    for (const auto& [a, p, q] : term.rim_corners) {
        const glm::dvec3 xa = lifted.get(a);
        angles += corner_angle(lifted.get(p) - xa, lifted.get(q) - xa);
    }
    const double defects = angles - term.offset;  // the interior vertices' angle defects' sum (Gauss-Bonnet)
    const double measured = defects / (kappa * kappa);
    // A single plane's mesh measures 0.8 to 1 of its area; another (flat pieces in several planes) keeps the area.
    const double k_area = measured > 0.5 * area && measured <= area * (1.0 + 1e-6) ? measured : area;
    term.weight_u = float(cross_u / k_area);
    term.weight_v = float(cross_v / k_area);
    return term;
}

void find_rim(GaussianCurvature& term, const std::vector<std::array<std::uint32_t, 3>>& triangles, std::size_t particles) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto& t : triangles) {
        for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
    }
    std::vector<char> rim(particles, 0), used(particles, 0);
    for (const auto& [edge, count] : uses) {
        used[edge.first] = used[edge.second] = 1;
        if (count == 1) rim[edge.first] = rim[edge.second] = 1;
    }
    term.rim_corners.clear();
    for (const auto& t : triangles) {
        for (int k = 0; k < 3; ++k) {
            if (rim[t[k]]) term.rim_corners.push_back({t[k], t[(k + 1) % 3], t[(k + 2) % 3]});
        }
    }
    std::size_t interior = 0;
    for (std::size_t i = 0; i < particles; ++i) interior += used[i] && !rim[i];
    term.offset = std::numbers::pi * double(triangles.size()) - 2.0 * std::numbers::pi * double(interior);
}

template <class F>
void accumulate_gaussian_forces(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                                BasicVec3Array<F>& force) {
    using Vec = glm::vec<3, F>;
    visit_gaussian_forces(topology, position, springs, [&](std::uint32_t i, const glm::dvec3& f) { force.add(i, Vec(f)); });
}

namespace {

#define CLOTHSIM_AVX512 __attribute__((target("avx512f,avx512vl,avx2,fma")))

// (x x + y y) + z z of eight vectors, glm::dot's order.
CLOTHSIM_AVX512 inline __m512d dot8(const __m512d* x, const __m512d* y) {
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(x[0], y[0]), _mm512_mul_pd(x[1], y[1])), _mm512_mul_pd(x[2], y[2]));
}

// Corners [first, first + 8) (fewer at the end): each one's forces on a, p and q, rounded to float, into out[vertex
// 0..2][axis][lane]; live lanes with a normal in `valid`.
CLOTHSIM_AVX512 __mmask8 corners_avx512(const GaussianCurvature& term, const DVec3Array& position, double c,
                                        std::size_t first, float (&out)[3][3][8]) {
    const std::size_t count = std::min<std::size_t>(8, term.rim_corners.size() - first);
    const __mmask8 live = count == 8 ? __mmask8(0xFF) : __mmask8((1u << count) - 1u);
    const int* base = reinterpret_cast<const int*>(term.rim_corners.data() + first);
    const __m256i stride = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
    const double* p[3] = {position.x.data(), position.y.data(), position.z.data()};
    __m512d x[3][3];  // [vertex a, p, q][axis]
    for (int k = 0; k < 3; ++k) {
        const __m256i index = _mm256_mmask_i32gather_epi32(_mm256_setzero_si256(), live, stride, base + k, 4);
        for (int axis = 0; axis < 3; ++axis) x[k][axis] = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), live, index, p[axis], 8);
    }
    __m512d e1[3], e2[3];
    for (int axis = 0; axis < 3; ++axis) {
        e1[axis] = _mm512_sub_pd(x[1][axis], x[0][axis]);
        e2[axis] = _mm512_sub_pd(x[2][axis], x[0][axis]);
    }
    const __m512d e11 = dot8(e1, e1), e22 = dot8(e2, e2), e12 = dot8(e1, e2);
    const __m512d area2 = _mm512_sub_pd(_mm512_mul_pd(e11, e22), _mm512_mul_pd(e12, e12));
    const __mmask8 valid = live & _mm512_cmp_pd_mask(area2, _mm512_setzero_pd(), _CMP_GT_OQ);
    const __m512d one = _mm512_set1_pd(1.0);
    const __m512d r = _mm512_div_pd(_mm512_set1_pd(c),
                                    _mm512_mul_pd(_mm512_mul_pd(_mm512_mask_sqrt_pd(one, valid, area2), e11), e22));
    const __m512d rp = _mm512_mul_pd(r, e22), rq = _mm512_mul_pd(r, e11);
    for (int axis = 0; axis < 3; ++axis) {
        const __m512d fp = _mm512_mul_pd(rp, _mm512_sub_pd(_mm512_mul_pd(e1[axis], e12), _mm512_mul_pd(e2[axis], e11)));
        const __m512d fq = _mm512_mul_pd(rq, _mm512_sub_pd(_mm512_mul_pd(e2[axis], e12), _mm512_mul_pd(e1[axis], e22)));
        const __m512d fa = _mm512_mul_pd(_mm512_add_pd(fp, fq), _mm512_set1_pd(-1.0));  // -(fp + fq), signed zeros too
        _mm256_storeu_ps(out[0][axis], _mm512_maskz_cvtpd_ps(__mmask8(0xFF), fa));
        _mm256_storeu_ps(out[1][axis], _mm512_maskz_cvtpd_ps(__mmask8(0xFF), fp));
        _mm256_storeu_ps(out[2][axis], _mm512_maskz_cvtpd_ps(__mmask8(0xFF), fq));
    }
    return valid;
}

}  // namespace

void gaussian_corner_forces(const GaussianCurvature& term, const DVec3Array& position, double c, std::size_t first,
                            std::size_t last, Vec3Array& out, std::size_t slot) {
    if (FastSolver::kernel() == FastKernel::Avx512) {
        float f[3][3][8];
        for (std::size_t at = first; at < last; at += 8) {
            const __mmask8 valid = corners_avx512(term, position, c, at, f);
            for (std::size_t lane = 0; lane < 8 && at + lane < last; ++lane) {
                const bool set = valid >> lane & 1u;
                for (int k = 0; k < 3; ++k) {
                    out.set(slot + 3 * (at + lane - first) + k,
                            set ? glm::vec3(f[k][0][lane], f[k][1][lane], f[k][2][lane]) : glm::vec3(0.0f));
                }
            }
        }
        return;
    }
    for (std::size_t at = first; at < last; ++at) {
        const auto& [a, p, q] = term.rim_corners[at];
        glm::dvec3 f[3];
        const bool set = corner_forces(position.get(a), position.get(p), position.get(q), c, f[0], f[1], f[2]);
        for (int k = 0; k < 3; ++k) out.set(slot + 3 * (at - first) + k, set ? glm::vec3(f[k]) : glm::vec3(0.0f));
    }
}

void accumulate_gaussian_forces_fast(const Topology& topology, const DVec3Array& position, const SpringSettings& springs,
                                     Vec3Array& force) {
    const double c = gaussian_coefficient(topology.gaussian, springs);
    if (c == 0.0) return;
    if (FastSolver::kernel() != FastKernel::Avx512) {
        accumulate_gaussian_forces(topology, position, springs, force);
        return;
    }
    const auto& corners = topology.gaussian.rim_corners;
    float out[3][3][8];
    for (std::size_t first = 0; first < corners.size(); first += 8) {
        const __mmask8 valid = corners_avx512(topology.gaussian, position, c, first, out);
        for (std::size_t lane = 0; lane < 8 && first + lane < corners.size(); ++lane) {
            if (!(valid >> lane & 1u)) continue;
            for (int k = 0; k < 3; ++k) {
                force.add(corners[first + lane][k], glm::vec3(out[k][0][lane], out[k][1][lane], out[k][2][lane]));
            }
        }
    }
}

double gaussian_energy(const Topology& topology, const DVec3Array& position, const SpringSettings& springs) {
    const double c = gaussian_coefficient(topology.gaussian, springs);
    if (c == 0.0 || topology.gaussian.rim_corners.empty()) return 0.0;
    double angles = 0.0;
    for (const auto& [a, p, q] : topology.gaussian.rim_corners) {
        const glm::dvec3 xa = position.get(a);
        angles += corner_angle(position.get(p) - xa, position.get(q) - xa);
    }
    return c * (topology.gaussian.offset - angles);
}

template void accumulate_gaussian_forces<float>(const Topology&, const DVec3Array&, const SpringSettings&, Vec3Array&);
template void accumulate_gaussian_forces<double>(const Topology&, const DVec3Array&, const SpringSettings&, DVec3Array&);

}  // namespace clothsim
