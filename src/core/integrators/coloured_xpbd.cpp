#include "integrators/coloured_xpbd.hpp"

#include "integrators/fast_solver.hpp"
#include "integrators/work_team.hpp"
#include "integrators/xpbd_projection.hpp"
#include "model/forces.hpp"
#include "model/gaussian_curvature.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <immintrin.h>

namespace clothsim {
namespace {

// Greedy colouring of `count` elements whose particles particles_of(j) lists (Welsh & Powell 1967, in list
// order): element j takes the lowest colour none of its particles has yet. Nullopt past kMaxColours.
template <class Particles>
std::optional<ColouredXpbd::Colours> colour(std::size_t count, std::size_t particle_count, Particles particles_of) {
    std::vector<std::uint64_t> used(particle_count, 0);  // bit c: a coloured element of colour c touches it
    std::vector<std::uint8_t> colour_of(count, 0);
    std::array<std::uint32_t, ColouredXpbd::kMaxColours> size{};
    int colours = 0;
    for (std::size_t j = 0; j < count; ++j) {
        std::uint64_t taken = 0;
        for (std::uint32_t p : particles_of(j)) taken |= used[p];
        if (taken == ~std::uint64_t{0}) return std::nullopt;
        const int c = std::countr_one(taken);
        for (std::uint32_t p : particles_of(j)) used[p] |= std::uint64_t{1} << c;
        colour_of[j] = static_cast<std::uint8_t>(c);
        ++size[static_cast<std::size_t>(c)];
        colours = std::max(colours, c + 1);
    }
    ColouredXpbd::Colours out;
    out.begin.assign(static_cast<std::size_t>(colours) + 1, 0);
    for (int c = 0; c < colours; ++c) out.begin[static_cast<std::size_t>(c) + 1] = out.begin[static_cast<std::size_t>(c)] + size[static_cast<std::size_t>(c)];
    std::vector<std::uint32_t> next(out.begin.begin(), out.begin.end() - 1);
    out.order.resize(count);
    for (std::size_t j = 0; j < count; ++j) out.order[next[colour_of[j]]++] = static_cast<std::uint32_t>(j);
    return out;
}

// Eight elements of one colour at a time with AVX-512: their particles gathered, the projection of
// xpbd_projection.hpp computed lane by lane in the same order of operations (so the same bits), the particles
// and multipliers scattered back where the element is projected (k != 0, and for a spring a length over
// 1e-12). A colour's elements share no particle, so the eight never write the same place. Each returns the
// sum of C^2 over [begin, end) added element by element in order, as the scalar loop adds it; the elements
// past the last whole eight run the scalar projection.

// base[index] for eight indices (the masked form: GCC 12 warns that the plain form's undefined source is
// used uninitialised, as it does for the plain sqrt and conversion).
__attribute__((target("avx512f,avx512vl,avx2,fma"))) inline __m512d gather(const double* base, __m256i index) {
    return _mm512_mask_i32gather_pd(_mm512_setzero_pd(), 0xFF, index, base, 8);
}
__attribute__((target("avx512f,avx512vl,avx2,fma"))) inline __m512d gather_wide(const float* base, __m256i index) {
    return _mm512_maskz_cvtps_pd(0xFF, _mm256_i32gather_ps(base, index, 4));
}
// -v, as the scalar unary minus: the sign bit flipped (AVX-512F has no floating-point xor).
__attribute__((target("avx512f,avx512vl,avx2,fma"))) inline __m512d negate(__m512d v) {
    return _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(v), _mm512_set1_epi64(std::int64_t(1) << 63)));
}
__attribute__((target("avx512f,avx512vl,avx2,fma"))) inline __m256i load8(const std::int32_t* p) {
    return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
}

}  // namespace

// One spring of the colour pass (entry e of the colour order), by project_spring on its stored data.
inline double ColouredXpbd::spring_one(State& state, std::uint32_t e, XpbdMultipliers& multipliers) const {
    const SpringData& d = spring_data_;
    double& lambda = multipliers.spring[springs_.order[e]];
    lambda = 0.0;  // until projected (the step does not clear them)
    if (d.k[e] == 0.0) return 0.0;
    const SpringCurve* curve = d.curve.empty() || d.curve[e].knots == 0 ? nullptr : &d.curve[e];
    return project_spring(state, static_cast<std::size_t>(d.a[e]), static_cast<std::size_t>(d.b[e]), d.rest[e],
                          d.alpha[e], lambda, curve);
}

// One hinge of the colour pass, by project_hinge on its stored data.
inline double ColouredXpbd::hinge_one(State& state, std::uint32_t e, XpbdMultipliers& multipliers) const {
    const HingeData& d = hinge_data_;
    glm::dvec3& lambda = multipliers.hinge[hinges_.order[e]];
    lambda = glm::dvec3(0.0);  // until projected (the step does not clear them)
    if (d.k[e] == 0.0) return 0.0;
    std::array<std::size_t, 4> v;
    std::array<double, 4> c;
    for (std::size_t i = 0; i < 4; ++i) v[i] = static_cast<std::size_t>(d.v[i][e]), c[i] = d.c[i][e];
    return project_hinge(state, v, c, d.alpha[e], lambda);
}

__attribute__((target("avx512f,avx512vl,avx2,fma"))) double ColouredXpbd::springs_avx512(
    State& state, std::uint32_t begin, std::uint32_t end, XpbdMultipliers& multipliers) const {
    const SpringData& d = spring_data_;
    double* x = state.position.x.data();
    double* y = state.position.y.data();
    double* z = state.position.z.data();
    const float* w = state.inverse_mass.data();
    double* lambdas = multipliers.spring.data();
    const std::int32_t* order = reinterpret_cast<const std::int32_t*>(springs_.order.data());
    const __m512d zero = _mm512_setzero_pd(), shortest = _mm512_set1_pd(1e-12);
    double violation = 0.0;
    std::uint32_t e = begin;
    // Two batches of eight at once, every gather before any scatter: a gather waits for the scatters before it
    // (the core cannot tell that they touch other particles), so one batch at a time runs its gathers, square
    // root and divides back to back; two overlap.
    constexpr std::uint32_t kBatches = 2;
    for (; e + 8 * kBatches <= end; e += 8 * kBatches) {
        __m256i va[kBatches], vb[kBatches];
        __m512d xa[kBatches], ya[kBatches], za[kBatches], xb[kBatches], yb[kBatches], zb[kBatches];
        __m512d dx[kBatches], dy[kBatches], dz[kBatches], c[kBatches], lambda[kBatches], ta[kBatches], tb[kBatches];
        __mmask8 on[kBatches];
        for (std::uint32_t u = 0; u < kBatches; ++u) {
            const std::uint32_t f = e + 8 * u;
            va[u] = load8(d.a.data() + f), vb[u] = load8(d.b.data() + f);
            xa[u] = gather(x, va[u]), ya[u] = gather(y, va[u]), za[u] = gather(z, va[u]);
            xb[u] = gather(x, vb[u]), yb[u] = gather(y, vb[u]), zb[u] = gather(z, vb[u]);
        }
        for (std::uint32_t u = 0; u < kBatches; ++u) {
            const std::uint32_t f = e + 8 * u;
            const __m512d wa = gather_wide(w, va[u]), wb = gather_wide(w, vb[u]);
            dx[u] = _mm512_sub_pd(xb[u], xa[u]), dy[u] = _mm512_sub_pd(yb[u], ya[u]), dz[u] = _mm512_sub_pd(zb[u], za[u]);
            const __m512d length = _mm512_maskz_sqrt_pd(
                0xFF, _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx[u], dx[u]), _mm512_mul_pd(dy[u], dy[u])),
                                    _mm512_mul_pd(dz[u], dz[u])));
            on[u] = _mm512_cmp_pd_mask(_mm512_loadu_pd(d.k.data() + f), zero, _CMP_NEQ_UQ) &
                    _mm512_cmp_pd_mask(length, shortest, _CMP_GT_OQ);
            c[u] = _mm512_sub_pd(length, _mm512_loadu_pd(d.rest.data() + f));
            lambda[u] = _mm512_div_pd(negate(c[u]), _mm512_add_pd(_mm512_add_pd(wa, wb), _mm512_loadu_pd(d.alpha.data() + f)));
            const __m512d g = _mm512_div_pd(lambda[u], length);
            ta[u] = negate(_mm512_mul_pd(wa, g)), tb[u] = _mm512_mul_pd(wb, g);
        }
        for (std::uint32_t u = 0; u < kBatches; ++u) {
            const __mmask8 m = on[u];
            _mm512_mask_i32scatter_pd(x, m, va[u], _mm512_add_pd(xa[u], _mm512_mul_pd(dx[u], ta[u])), 8);
            _mm512_mask_i32scatter_pd(y, m, va[u], _mm512_add_pd(ya[u], _mm512_mul_pd(dy[u], ta[u])), 8);
            _mm512_mask_i32scatter_pd(z, m, va[u], _mm512_add_pd(za[u], _mm512_mul_pd(dz[u], ta[u])), 8);
            _mm512_mask_i32scatter_pd(x, m, vb[u], _mm512_add_pd(xb[u], _mm512_mul_pd(dx[u], tb[u])), 8);
            _mm512_mask_i32scatter_pd(y, m, vb[u], _mm512_add_pd(yb[u], _mm512_mul_pd(dy[u], tb[u])), 8);
            _mm512_mask_i32scatter_pd(z, m, vb[u], _mm512_add_pd(zb[u], _mm512_mul_pd(dz[u], tb[u])), 8);
            // Every lane's multiplier, 0 where the element is not projected (as the list order leaves it).
            _mm512_i32scatter_pd(lambdas, load8(order + e + 8 * u), _mm512_maskz_mov_pd(m, lambda[u]), 8);
            alignas(64) double cc[8];
            _mm512_store_pd(cc, _mm512_mul_pd(c[u], c[u]));
            for (int l = 0; l < 8; ++l) {
                if (m & (1u << l)) violation += cc[l];
            }
        }
    }
    for (; e < end; ++e) violation += spring_one(state, e, multipliers);
    return violation;
}

// hinge_difference (forces.hpp) of one coordinate: relative to v[0], c1 (q1 - q0) + c2 (q2 - q0) + c3 (q3 - q0),
// summed left to right.
__attribute__((target("avx512f,avx512vl,avx2,fma"))) static inline __m512d hinge_difference8(const __m512d* q,
                                                                                            const __m512d* c) {
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(c[1], _mm512_sub_pd(q[1], q[0])),
                                       _mm512_mul_pd(c[2], _mm512_sub_pd(q[2], q[0]))),
                         _mm512_mul_pd(c[3], _mm512_sub_pd(q[3], q[0])));
}

__attribute__((target("avx512f,avx512vl,avx2,fma"))) double ColouredXpbd::hinges_avx512(
    State& state, std::uint32_t begin, std::uint32_t end, XpbdMultipliers& multipliers) const {
    const HingeData& d = hinge_data_;
    double* x = state.position.x.data();
    double* y = state.position.y.data();
    double* z = state.position.z.data();
    const float* w = state.inverse_mass.data();
    glm::dvec3* lambdas = multipliers.hinge.data();
    const __m512d zero = _mm512_setzero_pd(), minus_one = _mm512_set1_pd(-1.0);
    double violation = 0.0;
    std::uint32_t e = begin;
    // One batch at a time: two at once (as springs_avx512) measured no faster here, the registers spill; a
    // hinge's sixteen gathers and twelve scatters per eight are what it waits for.
    for (; e + 8 <= end; e += 8) {
        __m256i vi[4];
        __m512d px[4], py[4], pz[4], ci[4], t[4];
        __m512d sum_w = zero;
        for (int i = 0; i < 4; ++i) {
            vi[i] = load8(d.v[i].data() + e);
            px[i] = gather(x, vi[i]), py[i] = gather(y, vi[i]), pz[i] = gather(z, vi[i]);
            ci[i] = _mm512_loadu_pd(d.c[i].data() + e);
            const __m512d wi = gather_wide(w, vi[i]);
            sum_w = _mm512_add_pd(sum_w, _mm512_mul_pd(_mm512_mul_pd(wi, ci[i]), ci[i]));
            t[i] = _mm512_mul_pd(wi, ci[i]);
        }
        const __mmask8 on = _mm512_cmp_pd_mask(_mm512_loadu_pd(d.k.data() + e), zero, _CMP_NEQ_UQ);
        const __m512d cx = hinge_difference8(px, ci), cy = hinge_difference8(py, ci), cz = hinge_difference8(pz, ci);
        const __m512d scale = _mm512_div_pd(minus_one, _mm512_add_pd(sum_w, _mm512_loadu_pd(d.alpha.data() + e)));
        const __m512d lambda_x = _mm512_mul_pd(cx, scale), lambda_y = _mm512_mul_pd(cy, scale),
                      lambda_z = _mm512_mul_pd(cz, scale);
        for (int i = 0; i < 4; ++i) {
            _mm512_mask_i32scatter_pd(x, on, vi[i], _mm512_add_pd(px[i], _mm512_mul_pd(t[i], lambda_x)), 8);
            _mm512_mask_i32scatter_pd(y, on, vi[i], _mm512_add_pd(py[i], _mm512_mul_pd(t[i], lambda_y)), 8);
            _mm512_mask_i32scatter_pd(z, on, vi[i], _mm512_add_pd(pz[i], _mm512_mul_pd(t[i], lambda_z)), 8);
        }
        alignas(64) double lx[8], ly[8], lz[8], cc[8];
        _mm512_store_pd(lx, lambda_x), _mm512_store_pd(ly, lambda_y), _mm512_store_pd(lz, lambda_z);
        _mm512_store_pd(cc, _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(cx, cx), _mm512_mul_pd(cy, cy)), _mm512_mul_pd(cz, cz)));
        for (int l = 0; l < 8; ++l) {
            const bool projected = on & (1u << l);
            lambdas[hinges_.order[e + static_cast<std::uint32_t>(l)]] = projected ? glm::dvec3(lx[l], ly[l], lz[l]) : glm::dvec3(0.0);
            if (projected) violation += cc[l];
        }
    }
    for (; e < end; ++e) violation += hinge_one(state, e, multipliers);
    return violation;
}

// (x x + y y) + z z, glm::dot's order.
__attribute__((target("avx512f,avx512vl,avx2,fma"))) static inline __m512d dot8(const __m512d* a, const __m512d* b) {
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(a[0], b[0]), _mm512_mul_pd(a[1], b[1])), _mm512_mul_pd(a[2], b[2]));
}

// ((w_0 a_0) b_0 + (w_1 a_1) b_1) + (w_2 a_2) b_2.
__attribute__((target("avx512f,avx512vl,avx2,fma"))) static inline __m512d weighted_sum3(const __m512d* w, const __m512d* a,
                                                                                        const __m512d* b) {
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(_mm512_mul_pd(w[0], a[0]), b[0]), _mm512_mul_pd(_mm512_mul_pd(w[1], a[1]), b[1])),
                         _mm512_mul_pd(_mm512_mul_pd(w[2], a[2]), b[2]));
}
// a b - c d.
__attribute__((target("avx512f,avx512vl,avx2,fma"))) static inline __m512d products_difference(__m512d a, __m512d b, __m512d c, __m512d d) {
    return _mm512_sub_pd(_mm512_mul_pd(a, b), _mm512_mul_pd(c, d));
}
// -((r_0 c_0 + r_1 c_1) + r_2 c_2) / det.
__attribute__((target("avx512f,avx512vl,avx2,fma"))) static inline __m512d adjugate_row_solve(
    __m512d r0, __m512d r1, __m512d r2, __m512d c0, __m512d c1, __m512d c2, __m512d det) {
    return _mm512_div_pd(negate(_mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(r0, c0), _mm512_mul_pd(r1, c1)), _mm512_mul_pd(r2, c2))), det);
}

// project_membrane (xpbd_projection.hpp) eight at a time, for a linear material with shear (C66 > 0): every
// operation of the scalar form in its order; a collapsed triangle (|w| <= 1e-12) or a compliance that is not
// positive is left alone, as there.
__attribute__((target("avx512f,avx512vl,avx2,fma"))) double ColouredXpbd::membranes_avx512(
    State& state, const Topology& topology, const SpringSettings& springs, std::uint32_t begin, std::uint32_t end,
    const MembraneTensor& c, double h, XpbdMultipliers& multipliers) const {
    const MembraneData& d = membrane_data_;
    double* p[3] = {state.position.x.data(), state.position.y.data(), state.position.z.data()};
    const float* inverse_mass = state.inverse_mass.data();
    glm::dvec3* lambdas = multipliers.membrane.data();
    const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0), two = _mm512_set1_pd(2.0),
                  tiny = _mm512_set1_pd(1e-12), h2 = _mm512_set1_pd(h * h);
    const __m512d c11 = _mm512_set1_pd(c.c11), c22 = _mm512_set1_pd(c.c22), c12 = _mm512_set1_pd(c.c12), c66 = _mm512_set1_pd(c.c66);
    double violation = 0.0;
    std::uint32_t e = begin;
    for (; e + 8 <= end; e += 8) {
        __m256i vi[3];
        __m512d x[3][3], w[3], bu[3], bv[3];  // x[corner][axis]
        for (int i = 0; i < 3; ++i) {
            vi[i] = load8(d.v[static_cast<std::size_t>(i)].data() + e);
            for (int k = 0; k < 3; ++k) x[i][k] = gather(p[k], vi[i]);
            w[i] = gather_wide(inverse_mass, vi[i]);
            bu[i] = _mm512_loadu_pd(d.bu[static_cast<std::size_t>(i)].data() + e);
            bv[i] = _mm512_loadu_pd(d.bv[static_cast<std::size_t>(i)].data() + e);
        }
        const __m512d area = _mm512_loadu_pd(d.area.data() + e);
        // membrane_strain: w = b_1 (x_1 - x_0) + b_2 (x_2 - x_0), e = (q - 1) / (|w| + 1), gamma = w_u . w_v.
        __m512d wu[3], wv[3];
        for (int k = 0; k < 3; ++k) {
            const __m512d d1 = _mm512_sub_pd(x[1][k], x[0][k]), d2 = _mm512_sub_pd(x[2][k], x[0][k]);
            wu[k] = _mm512_add_pd(_mm512_mul_pd(bu[1], d1), _mm512_mul_pd(bu[2], d2));
            wv[k] = _mm512_add_pd(_mm512_mul_pd(bv[1], d1), _mm512_mul_pd(bv[2], d2));
        }
        const __m512d qu = dot8(wu, wu), qv = dot8(wv, wv);
        const __m512d lu = _mm512_maskz_sqrt_pd(0xFF, qu), lv = _mm512_maskz_sqrt_pd(0xFF, qv);
        const __m512d eu = _mm512_div_pd(_mm512_sub_pd(qu, one), _mm512_add_pd(lu, one));
        const __m512d ev = _mm512_div_pd(_mm512_sub_pd(qv, one), _mm512_add_pd(lv, one));
        const __m512d gamma = dot8(wu, wv);
        // membrane_compliance, linear: K = A [[C11, C12], [C12, C22]], alpha~ = K^-1 / h^2; shear 1 / (A C66 h^2).
        const __m512d k11 = _mm512_mul_pd(area, c11), k22 = _mm512_mul_pd(area, c22), k12 = _mm512_mul_pd(area, c12);
        const __m512d kdet = _mm512_sub_pd(_mm512_mul_pd(k11, k22), _mm512_mul_pd(k12, k12));
        const __mmask8 on = _mm512_cmp_pd_mask(lu, tiny, _CMP_GT_OQ) & _mm512_cmp_pd_mask(lv, tiny, _CMP_GT_OQ) &
                            _mm512_cmp_pd_mask(k11, zero, _CMP_GT_OQ) & _mm512_cmp_pd_mask(k22, zero, _CMP_GT_OQ) &
                            _mm512_cmp_pd_mask(kdet, zero, _CMP_GT_OQ);
        const __m512d dh = _mm512_mul_pd(kdet, h2);
        const __m512d al00 = _mm512_div_pd(k22, dh), al11 = _mm512_div_pd(k11, dh), al01 = _mm512_div_pd(negate(k12), dh);
        const __m512d al22 = _mm512_div_pd(one, _mm512_mul_pd(_mm512_mul_pd(area, c66), h2));
        __m512d nu[3], nv[3];
        for (int k = 0; k < 3; ++k) nu[k] = _mm512_div_pd(wu[k], lu), nv[k] = _mm512_div_pd(wv[k], lv);
        const __m512d suu = weighted_sum3(w, bu, bu), svv = weighted_sum3(w, bv, bv), suv = weighted_sum3(w, bu, bv);
        const __m512d a00 = _mm512_add_pd(al00, _mm512_mul_pd(suu, dot8(nu, nu)));
        const __m512d a11 = _mm512_add_pd(al11, _mm512_mul_pd(svv, dot8(nv, nv)));
        const __m512d a01 = _mm512_add_pd(al01, _mm512_mul_pd(suv, dot8(nu, nv)));
        const __m512d a02 = _mm512_add_pd(_mm512_mul_pd(suu, dot8(nu, wv)), _mm512_mul_pd(suv, dot8(nu, wu)));
        const __m512d a12 = _mm512_add_pd(_mm512_mul_pd(suv, dot8(nv, wv)), _mm512_mul_pd(svv, dot8(nv, wu)));
        const __m512d a22 = _mm512_add_pd(_mm512_add_pd(al22, _mm512_add_pd(_mm512_mul_pd(suu, dot8(wv, wv)),
                                                                             _mm512_mul_pd(_mm512_mul_pd(two, suv), gamma))),
                                          _mm512_mul_pd(svv, dot8(wu, wu)));
        const __m512d m00 = products_difference(a11, a22, a12, a12), m01 = products_difference(a02, a12, a01, a22), m02 = products_difference(a01, a12, a02, a11);
        const __m512d m11 = products_difference(a00, a22, a02, a02), m12 = products_difference(a01, a02, a00, a12), m22 = products_difference(a00, a11, a01, a01);
        const __m512d det = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(a00, m00), _mm512_mul_pd(a01, m01)), _mm512_mul_pd(a02, m02));
        const __m512d l0 = adjugate_row_solve(m00, m01, m02, eu, ev, gamma, det);
        const __m512d l1 = adjugate_row_solve(m01, m11, m12, eu, ev, gamma, det);
        const __m512d l2 = adjugate_row_solve(m02, m12, m22, eu, ev, gamma, det);
        for (int k = 0; k < 3; ++k) {
            const __m512d P = _mm512_add_pd(_mm512_mul_pd(l0, nu[k]), _mm512_mul_pd(l2, wv[k]));
            const __m512d Q = _mm512_add_pd(_mm512_mul_pd(l1, nv[k]), _mm512_mul_pd(l2, wu[k]));
            for (int i = 0; i < 3; ++i) {
                const __m512d moved = _mm512_add_pd(x[i][k], _mm512_add_pd(_mm512_mul_pd(_mm512_mul_pd(w[i], bu[i]), P),
                                                                           _mm512_mul_pd(_mm512_mul_pd(w[i], bv[i]), Q)));
                _mm512_mask_i32scatter_pd(p[k], on, vi[i], moved, 8);
            }
        }
        alignas(64) double o0[8], o1[8], o2[8], cc[8];
        _mm512_store_pd(o0, l0), _mm512_store_pd(o1, l1), _mm512_store_pd(o2, l2);
        _mm512_store_pd(cc, _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(eu, eu), _mm512_mul_pd(ev, ev)), _mm512_mul_pd(gamma, gamma)));
        for (int l = 0; l < 8; ++l) {
            const bool projected = on & (1u << l);
            lambdas[membranes_.order[e + static_cast<std::uint32_t>(l)]] = projected ? glm::dvec3(o0[l], o1[l], o2[l]) : glm::dvec3(0.0);
            if (projected) violation += cc[l];
        }
    }
    for (; e < end; ++e) {
        const std::uint32_t j = membranes_.order[e];
        violation += project_membrane(state, topology.membranes[j], c, springs, h, multipliers.membrane[j]);
    }
    return violation;
}

std::optional<ColouredXpbd> ColouredXpbd::for_topology(const Topology& topology) {
    std::size_t n = 0;  // the particles the elements reach
    for (const Spring& s : topology.springs) n = std::max<std::size_t>(n, std::max(s.a, s.b) + std::size_t{1});
    for (const Bend& b : topology.bends) n = std::max<std::size_t>(n, std::max({b.a, b.m, b.b}) + std::size_t{1});
    for (const Hinge& h : topology.hinges) n = std::max<std::size_t>(n, *std::max_element(h.v.begin(), h.v.end()) + std::size_t{1});
    for (const Membrane& m : topology.membranes) n = std::max<std::size_t>(n, *std::max_element(m.v.begin(), m.v.end()) + std::size_t{1});
    ColouredXpbd out;
    auto springs = colour(topology.springs.size(), n, [&](std::size_t j) {
        return std::array<std::uint32_t, 2>{topology.springs[j].a, topology.springs[j].b};
    });
    auto bends = colour(topology.bends.size(), n, [&](std::size_t j) {
        const Bend& b = topology.bends[j];
        return std::array<std::uint32_t, 3>{b.a, b.m, b.b};
    });
    auto hinges = colour(topology.hinges.size(), n, [&](std::size_t j) { return topology.hinges[j].v; });
    auto membranes = colour(topology.membranes.size(), n, [&](std::size_t j) { return topology.membranes[j].v; });
    if (!springs || !bends || !hinges || !membranes) return std::nullopt;
    out.membranes_ = std::move(*membranes);
    out.springs_ = std::move(*springs);
    out.bends_ = std::move(*bends);
    out.hinges_ = std::move(*hinges);
    // The data in colour order.
    SpringData& sd = out.spring_data_;
    for (std::uint32_t j : out.springs_.order) {
        const Spring& s = topology.springs[j];
        sd.a.push_back(static_cast<std::int32_t>(s.a));
        sd.b.push_back(static_cast<std::int32_t>(s.b));
        sd.rest.push_back(static_cast<double>(s.rest_length));
    }
    HingeData& hd = out.hinge_data_;
    for (std::uint32_t j : out.hinges_.order) {
        for (int i = 0; i < 4; ++i) {
            hd.v[static_cast<std::size_t>(i)].push_back(static_cast<std::int32_t>(topology.hinges[j].v[static_cast<std::size_t>(i)]));
            hd.c[static_cast<std::size_t>(i)].push_back(double(topology.hinges[j].c[static_cast<std::size_t>(i)]));
        }
    }
    MembraneData& md = out.membrane_data_;
    for (std::uint32_t j : out.membranes_.order) {
        const Membrane& m = topology.membranes[j];
        for (std::size_t i = 0; i < 3; ++i) {
            md.v[i].push_back(static_cast<std::int32_t>(m.v[i]));
            md.bu[i].push_back(double(m.bu[i]));
            md.bv[i].push_back(double(m.bv[i]));
        }
        md.area.push_back(double(m.area));
    }
    return out;
}

void ColouredXpbd::set_stiffness(const Topology& topology, const SpringSettings& springs) {
    spring_data_.k.clear();
    for (std::uint32_t j : springs_.order) spring_data_.k.push_back(stiffness_of(springs, topology.springs[j]));
    spring_data_.curve.clear();
    if (has_curves(springs)) {  // curve_of: a grid's by axis, a mesh cloth's by warp level
        for (std::uint32_t j : springs_.order) spring_data_.curve.push_back(curve_of(springs, topology.springs[j]));
    }
    hinge_data_.k.clear();
    for (std::uint32_t j : hinges_.order) hinge_data_.k.push_back(stiffness_of(springs, topology.hinges[j]));
    alpha_h_ = 0.0;
}

// alpha~ = 1 / (k w h^2) for the substep h, computed as the list order computes it.
void ColouredXpbd::set_substep(double h) {
    if (h == alpha_h_) return;
    auto fill = [h](const std::vector<double>& k, std::vector<double>& alpha) {
        alpha.resize(k.size());
        for (std::size_t e = 0; e < k.size(); ++e) alpha[e] = 1.0 / (k[e] * h * h);
    };
    fill(spring_data_.k, spring_data_.alpha);
    fill(hinge_data_.k, hinge_data_.alpha);
    alpha_h_ = h;
}



void ColouredXpbd::step(State& state, const Dynamics& dynamics, const Topology& topology, const SpringSettings& springs,
                        double h, int threads, XpbdMultipliers& multipliers) {
    const std::size_t n = state.size();
    state.substep = h;
    set_substep(h);
    const bool automatic = threads == 0;
    const int wanted = std::clamp(threads > 0 ? threads : WorkTeam::cores(), 1, WorkTeam::kMaxThreads);
    int team = wanted;
    if (automatic && team > 1 && team_choice_.next_is_single()) team = 1;
    const auto began = std::chrono::steady_clock::now();
    WorkTeam& work_team = WorkTeam::shared();

    // Predict with the external accelerations, as step_xpbd.
    wind_.resize(n);
    dynamics.external(state, wind_);
    accumulate_gaussian_forces_fast(topology, state.position, springs, wind_);  // a force, not a constraint
    accelerations(state, wind_, dynamics.gravity, dynamics.damping, a_);
    start_ = state.position;
    for (std::size_t i = 0; i < n; ++i) {
        if (state.pinned[i]) continue;
        state.position.add(i, state.motion.get(i) + a_.get(i) * (h * h));  // x + h (v + h a)
    }

    // Every element's multiplier is written in its colour (0 where it is not projected), so they are not
    // cleared first; the bends' are (a mesh cloth has none).
    multipliers.spring.resize(topology.springs.size());
    multipliers.bend.assign(topology.bends.size(), glm::dvec3(0.0));
    multipliers.hinge.resize(topology.hinges.size());
    multipliers.membrane.resize(topology.membranes.size());
    // Each colour in pieces of kPiece elements (small enough that a descheduled thread holds up little:
    // work_team.hpp); each piece's sum of C^2 in its own slot, summed in piece order: the same for any team.
    // With the AVX-512 kernel (FastSolver's choice, so the tests run every kernel the CPU has), springs and
    // hinges eight at a time; the same bits as the scalar loop.
    constexpr std::uint32_t kPiece = 512;
    const bool wide = FastSolver::kernel() == FastKernel::Avx512;
    double violation2 = 0.0;
    auto project = [&](const Colours& colours, auto&& piece_of) {
        for (int c = 0; c < colours.count(); ++c) {
            const std::uint32_t first = colours.begin[static_cast<std::size_t>(c)];
            const std::uint32_t last = colours.begin[static_cast<std::size_t>(c) + 1];
            const int pieces = static_cast<int>((last - first + kPiece - 1) / kPiece);
            violation_.assign(static_cast<std::size_t>(pieces), 0.0);
            work_team.run(team, pieces, [&](int piece, int) {
                const std::uint32_t begin = first + static_cast<std::uint32_t>(piece) * kPiece;
                violation_[static_cast<std::size_t>(piece)] = piece_of(begin, std::min(last, begin + kPiece));
            });
            for (double v : violation_) violation2 += v;
        }
    };
    // A cloth of membrane triangles has edge springs of weight 0, which the list path skips one by one: none
    // is projected, their multipliers stay 0.
    if (!topology.membranes.empty()) {
        multipliers.spring.assign(topology.springs.size(), 0.0);
    } else {
        project(springs_, [&](std::uint32_t begin, std::uint32_t end) {
            if (wide && spring_data_.curve.empty()) return springs_avx512(state, begin, end, multipliers);
            double v = 0.0;
            for (std::uint32_t e = begin; e < end; ++e) v += spring_one(state, e, multipliers);
            return v;
        });
    }
    project(bends_, [&](std::uint32_t begin, std::uint32_t end) {  // a grid's: a mesh cloth has none
        double v = 0.0;
        for (std::uint32_t e = begin; e < end; ++e) {
            const std::uint32_t j = bends_.order[e];
            const double k = stiffness_of(springs, topology.bends[j]);
            if (k != 0.0) v += project_bend(state, topology.bends[j], k, h, multipliers.bend[j]);
        }
        return v;
    });
    project(hinges_, [&](std::uint32_t begin, std::uint32_t end) {
        if (wide) return hinges_avx512(state, begin, end, multipliers);
        double v = 0.0;
        for (std::uint32_t e = begin; e < end; ++e) v += hinge_one(state, e, multipliers);
        return v;
    });
    const MembraneTensor tensor = membrane_tensor(springs);
    // A linear membrane with shear, eight at a time with AVX-512 (the same bits as project_membrane).
    const bool wide_membranes = wide && springs.membrane_curve[0].knots == 0 && springs.membrane_curve[1].knots == 0 &&
                                tensor.c66 > 0.0;
    project(membranes_, [&](std::uint32_t begin, std::uint32_t end) {  // a mesh cloth's triangles
        if (wide_membranes) return membranes_avx512(state, topology, springs, begin, end, tensor, h, multipliers);
        double v = 0.0;
        for (std::uint32_t e = begin; e < end; ++e) {
            const std::uint32_t j = membranes_.order[e];
            v += project_membrane(state, topology.membranes[j], tensor, springs, h, multipliers.membrane[j]);
        }
        return v;
    });

    for (std::size_t i = 0; i < n; ++i) {
        state.motion.set(i, state.pinned[i] ? glm::dvec3(0.0) : state.position.get(i) - start_.get(i));
    }
    multipliers.substep = h;
    multipliers.initial_violation = std::sqrt(violation2);
    if (automatic && wanted > 1) team_choice_.record(team == 1, std::chrono::steady_clock::now() - began);
    last_threads_ = team;
}

}  // namespace clothsim
