#include "model/element_gather.hpp"

#include "integrators/fast_solver.hpp"
#include "integrators/work_team.hpp"
#include "model/forces.hpp"
#include "model/gaussian_curvature.hpp"
#include "model/membrane.hpp"

#include <glm/geometric.hpp>

#include <immintrin.h>

#include <algorithm>

namespace clothsim {
namespace {

// Pieces of this many elements or particles per job index: enough work to pay for a claim (a whole number of
// the AVX-512 sum's blocks of kLanes particles).
constexpr std::size_t kPiece = 1024;
constexpr std::size_t kLanes = 16;
static_assert(kPiece % kLanes == 0);


}  // namespace

ElementGather ElementGather::for_topology(const Topology& topology) {
    ElementGather g;
    // A cloth of membrane triangles has edge springs of weight 0, which no live change gives stiffness
    // (apply_fabric): they add nothing, and the gather leaves them out.
    g.springs = topology.membranes.empty() ? topology.springs.size() : 0;
    g.hinges = topology.hinges.size();
    g.membranes = topology.membranes.size();
    g.corners = topology.gaussian.rim_corners.size();
    const std::size_t n = static_cast<std::size_t>(topology.rows) * static_cast<std::size_t>(topology.cols);
    g.begin.assign(n + 1, 0);
    auto each = [&](auto&& visit) {  // in list order: springs, then hinges, then membranes, then rim corners
        for (std::size_t j = 0; j < g.springs; ++j) {
            visit(topology.springs[j].a, j, 1.0f);
            visit(topology.springs[j].b, j, -1.0f);
        }
        for (std::size_t h = 0; h < g.hinges; ++h) {
            for (std::size_t slot = 0; slot < 4; ++slot) visit(topology.hinges[h].v[slot], g.springs + h, -topology.hinges[h].c[slot]);
        }
        for (std::size_t m = 0; m < g.membranes; ++m) {
            const Membrane& t = topology.membranes[m];
            const std::size_t slot = g.springs + g.hinges + 2 * m;
            for (std::size_t i = 0; i < 3; ++i) {
                visit(t.v[i], slot, t.bu[i]);
                visit(t.v[i], slot + 1, t.bv[i]);
            }
        }
        for (std::size_t c = 0; c < g.corners; ++c) {
            const std::size_t slot = g.springs + g.hinges + 2 * g.membranes + 3 * c;
            for (std::size_t k = 0; k < 3; ++k) visit(topology.gaussian.rim_corners[c][k], slot + k, 1.0f);
        }
    };
    each([&](std::uint32_t particle, std::size_t, float) { ++g.begin[particle + 1]; });
    for (std::size_t i = 0; i < n; ++i) g.begin[i + 1] += g.begin[i];
    g.source.resize(g.begin[n]);
    g.coefficient.resize(g.begin[n]);
    std::vector<std::uint32_t> fill(g.begin.begin(), g.begin.end() - 1);
    each([&](std::uint32_t particle, std::size_t element, float c) {
        g.source[fill[particle]] = static_cast<std::uint32_t>(element);
        g.coefficient[fill[particle]++] = c;
    });
    g.element_force.resize(g.springs + g.hinges + 2 * g.membranes + 3 * g.corners);
    for (std::size_t j = 0; j < g.springs; ++j) {
        const Spring& sp = topology.springs[j];
        g.spring_a.push_back(static_cast<std::int32_t>(sp.a));
        g.spring_b.push_back(static_cast<std::int32_t>(sp.b));
        g.spring_rest.push_back(sp.rest_length);
        const bool v = sp.axis == Axis::V;
        g.spring_stiffness.push_back(sp.kind == SpringKind::Structural ? (v ? 1 : 0)
                                     : sp.kind == SpringKind::Shear    ? 2
                                                                       : (v ? 4 : 3));
    }
    g.set_weights(topology);
    for (const Hinge& h : topology.hinges) {
        for (std::size_t k = 0; k < 4; ++k) g.hinge_v[k].push_back(static_cast<std::int32_t>(h.v[k]));
        for (std::size_t k = 0; k < 3; ++k) g.hinge_c[k].push_back(h.c[k + 1]);
        g.hinge_weight_u.push_back(h.weight_u);
        g.hinge_weight_v.push_back(h.weight_v);
    }
    for (const Membrane& m : topology.membranes) {
        for (std::size_t k = 0; k < 3; ++k) g.membrane_v[k].push_back(static_cast<std::int32_t>(m.v[k]));
        g.membrane_b[0].push_back(m.bu[1]);
        g.membrane_b[1].push_back(m.bu[2]);
        g.membrane_b[2].push_back(m.bv[1]);
        g.membrane_b[3].push_back(m.bv[2]);
        g.membrane_area.push_back(m.area);
    }
    // The lane layout: block b holds particles 16 b .. 16 b + 15, padded to its longest list.
    const std::size_t blocks = (n + kLanes - 1) / kLanes;
    g.lanes_begin.assign(blocks + 1, 0);
    g.lane_terms.assign(blocks * kLanes, 0);
    for (std::size_t b = 0; b < blocks; ++b) {
        std::uint32_t longest = 0;
        for (std::size_t i = b * kLanes; i < std::min(n, (b + 1) * kLanes); ++i) {
            g.lane_terms[i] = g.begin[i + 1] - g.begin[i];
            longest = std::max(longest, g.lane_terms[i]);
        }
        g.lanes_begin[b + 1] = g.lanes_begin[b] + longest * static_cast<std::uint32_t>(kLanes);
    }
    g.lane_source.assign(g.lanes_begin[blocks], 0);
    g.lane_coefficient.assign(g.lanes_begin[blocks], 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t b = i / kLanes, lane = i % kLanes;
        for (std::uint32_t t = 0; t < g.lane_terms[i]; ++t) {
            g.lane_source[g.lanes_begin[b] + t * kLanes + lane] = g.source[g.begin[i] + t];
            g.lane_coefficient[g.lanes_begin[b] + t * kLanes + lane] = g.coefficient[g.begin[i] + t];
        }
    }
    return g;
}

void ElementGather::set_weights(const Topology& topology) {
    spring_weight.resize(topology.springs.size());
    for (std::size_t j = 0; j < topology.springs.size(); ++j) spring_weight[j] = topology.springs[j].weight;
}

namespace {

#define CLOTHSIM_AVX512 __attribute__((target("avx512f,avx512vl,avx2,fma")))

// The settings' stiffnesses in the order of ElementGather::spring_stiffness.
std::array<float, 8> stiffness_table(const SpringSettings& springs) {
    return {springs.structural.x, springs.structural.y, springs.shear, springs.bending.x, springs.bending.y, 0.0f, 0.0f, 0.0f};
}

// Springs [first, last): each one's force on its end a, eight at a time, with the scalar loop's operations in
// its order: d in double, rounded to float; |d| = sqrt((x x + y y) + z z); f = (k w (|d| - L) / |d|) d, k w d
// for a spring of no rest length, 0 for k w = 0 or |d| <= 1e-12.
CLOTHSIM_AVX512 void springs_avx512(ElementGather& g, const DVec3Array& position, const SpringSettings& springs,
                                    std::size_t first, std::size_t last) {
    const std::array<float, 8> table = stiffness_table(springs);
    const __m256 stiffness = _mm256_loadu_ps(table.data());
    const double *px = position.x.data(), *py = position.y.data(), *pz = position.z.data();
    for (std::size_t j = first; j < last; j += 8) {
        const __mmask8 live = last - j >= 8 ? __mmask8(0xFF) : __mmask8((1u << (last - j)) - 1u);
        const __m256i a = _mm256_maskz_loadu_epi32(live, &g.spring_a[j]), b = _mm256_maskz_loadu_epi32(live, &g.spring_b[j]);
        const __m512d zero = _mm512_setzero_pd();
        auto difference = [&](const double* p) CLOTHSIM_AVX512 {
            return _mm512_maskz_cvtpd_ps(__mmask8(0xFF), _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, live, b, p, 8),
                                                 _mm512_mask_i32gather_pd(zero, live, a, p, 8)));
        };
        const __m256 dx = difference(px), dy = difference(py), dz = difference(pz);
        const __m256 ks = _mm256_mul_ps(_mm256_permutevar8x32_ps(stiffness, _mm256_maskz_loadu_epi32(live, &g.spring_stiffness[j])),
                                        _mm256_maskz_loadu_ps(live, &g.spring_weight[j]));
        const __m256 rest = _mm256_maskz_loadu_ps(live, &g.spring_rest[j]);
        const __m256 length = _mm256_sqrt_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                                           _mm256_mul_ps(dz, dz)));
        const __m256 zero8 = _mm256_setzero_ps();
        // Per lane: k w for a spring of no rest length, k w (|d| - L) / |d| where |d| > 1e-12, else 0.
        const __mmask8 no_rest = _mm256_cmp_ps_mask(rest, zero8, _CMP_EQ_OQ);
        const __mmask8 long_enough = _mm256_cmp_ps_mask(length, _mm256_set1_ps(1e-12f), _CMP_GT_OQ);
        const __mmask8 stiff = _mm256_cmp_ps_mask(ks, zero8, _CMP_NEQ_UQ);
        __m256 scale = _mm256_maskz_div_ps(long_enough, _mm256_mul_ps(ks, _mm256_sub_ps(length, rest)), length);
        scale = _mm256_mask_mov_ps(scale, no_rest, ks);
        scale = _mm256_maskz_mov_ps(stiff & (no_rest | long_enough), scale);
        // A zero scale times d is +-0: store exact zeros where the scalar loop leaves f = 0.
        const __mmask8 set = live & stiff & (no_rest | long_enough);
        _mm256_mask_storeu_ps(&g.element_force.x[j], live, _mm256_maskz_mul_ps(set, scale, dx));
        _mm256_mask_storeu_ps(&g.element_force.y[j], live, _mm256_maskz_mul_ps(set, scale, dy));
        _mm256_mask_storeu_ps(&g.element_force.z[j], live, _mm256_maskz_mul_ps(set, scale, dz));
    }
}

// Hinges [first, last): each one's e = k sum_i c_i x_i, eight at a time, as hinge_difference computes the sum
// (relative to x_0, in double: (c_1 q_1 + c_2 q_2) + c_3 q_3), rounded to float, times k = b_u w_u + b_v w_v
// (0 where k = 0).
CLOTHSIM_AVX512 void hinges_avx512(ElementGather& g, const DVec3Array& position, const SpringSettings& springs,
                                   std::size_t first, std::size_t last) {
    const double* p[3] = {position.x.data(), position.y.data(), position.z.data()};
    float* out[3] = {g.element_force.x.data(), g.element_force.y.data(), g.element_force.z.data()};
    for (std::size_t h = first; h < last; h += 8) {
        const __mmask8 live = last - h >= 8 ? __mmask8(0xFF) : __mmask8((1u << (last - h)) - 1u);
        __m256i v[4];
        for (std::size_t k = 0; k < 4; ++k) v[k] = _mm256_maskz_loadu_epi32(live, &g.hinge_v[k][h]);
        __m512d c[3];
        for (std::size_t k = 0; k < 3; ++k) c[k] = _mm512_maskz_cvtps_pd(__mmask8(0xFF), _mm256_maskz_loadu_ps(live, &g.hinge_c[k][h]));
        const __m256 kh = _mm256_max_ps(
            _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(springs.bending.x), _mm256_maskz_loadu_ps(live, &g.hinge_weight_u[h])),
                          _mm256_mul_ps(_mm256_set1_ps(springs.bending.y), _mm256_maskz_loadu_ps(live, &g.hinge_weight_v[h]))),
            _mm256_setzero_ps());  // stiffness_of's max(0, k)
        const __mmask8 set = live & _mm256_cmp_ps_mask(kh, _mm256_setzero_ps(), _CMP_NEQ_UQ);
        const __m512d zero = _mm512_setzero_pd();
        const std::size_t at = g.springs + h;
        for (int axis = 0; axis < 3; ++axis) {
            const __m512d o = _mm512_mask_i32gather_pd(zero, live, v[0], p[axis], 8);
            __m512d q[3];
            for (std::size_t k = 0; k < 3; ++k) q[k] = _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, live, v[k + 1], p[axis], 8), o);
            const __m512d sum = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(c[0], q[0]), _mm512_mul_pd(c[1], q[1])), _mm512_mul_pd(c[2], q[2]));
            _mm256_mask_storeu_ps(out[axis] + at, live, _mm256_maskz_mul_ps(set, kh, _mm512_maskz_cvtpd_ps(__mmask8(0xFF), sum)));
        }
    }
}

// (x x + y y) + z z of eight vectors, glm::dot's order.
CLOTHSIM_AVX512 inline __m512d dot8(const __m512d* x, const __m512d* y) {
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(x[0], y[0]), _mm512_mul_pd(x[1], y[1])), _mm512_mul_pd(x[2], y[2]));
}

// Membranes [first, last) eight at a time, linear ones (no stretch curve), with membrane_forces' double
// operations in its order (membrane.hpp): w = b_1 (x_1 - x_0) + b_2 (x_2 - x_0), q = (x x + y y) + z z, |w| its
// square root, e = (q - 1) / (|w| + 1), the stresses, p = -A ((sigma / |w|) w + tau w'), each rounded once to float;
// a collapsed triangle's p_u and p_v 0. p_u and p_v go to the slots base + 2 m and the next, interleaved.
CLOTHSIM_AVX512 void membranes_avx512(ElementGather& g, const DVec3Array& position, const MembraneTensor& c,
                                      std::size_t first, std::size_t last) {
    const double* p[3] = {position.x.data(), position.y.data(), position.z.data()};
    float* out[3] = {g.element_force.x.data(), g.element_force.y.data(), g.element_force.z.data()};
    const __m512d one = _mm512_set1_pd(1.0), zero = _mm512_setzero_pd(), tiny = _mm512_set1_pd(1e-12);
    const __m512d c11 = _mm512_set1_pd(c.c11), c22 = _mm512_set1_pd(c.c22), c12 = _mm512_set1_pd(c.c12), c66 = _mm512_set1_pd(c.c66);
    // p_u lane l to 2 l, p_v lane l to 2 l + 1: lanes 0-3 in the low run, 4-7 in the high one.
    const __m512i low = _mm512_setr_epi64(0, 8, 1, 9, 2, 10, 3, 11), high = _mm512_setr_epi64(4, 12, 5, 13, 6, 14, 7, 15);
    const std::size_t base = g.springs + g.hinges;
    for (std::size_t m = first; m < last; m += 8) {
        const std::size_t count = std::min<std::size_t>(8, last - m);
        const __mmask8 live = static_cast<__mmask8>((1u << count) - 1u);
        const __mmask16 pairs = static_cast<__mmask16>((1u << (2 * count)) - 1u);
        __m256i v[3];
        for (std::size_t k = 0; k < 3; ++k) v[k] = _mm256_maskz_loadu_epi32(live, &g.membrane_v[k][m]);
        __m512d b[4];
        for (std::size_t k = 0; k < 4; ++k) b[k] = _mm512_maskz_cvtps_pd(__mmask8(0xFF), _mm256_maskz_loadu_ps(live, &g.membrane_b[k][m]));
        const __m512d area = _mm512_maskz_cvtps_pd(__mmask8(0xFF), _mm256_maskz_loadu_ps(live, &g.membrane_area[m]));
        __m512d wu[3], wv[3];
        for (int axis = 0; axis < 3; ++axis) {
            const __m512d o = _mm512_mask_i32gather_pd(zero, live, v[0], p[axis], 8);
            const __m512d d1 = _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, live, v[1], p[axis], 8), o);
            const __m512d d2 = _mm512_sub_pd(_mm512_mask_i32gather_pd(zero, live, v[2], p[axis], 8), o);
            wu[axis] = _mm512_add_pd(_mm512_mul_pd(b[0], d1), _mm512_mul_pd(b[1], d2));
            wv[axis] = _mm512_add_pd(_mm512_mul_pd(b[2], d1), _mm512_mul_pd(b[3], d2));
        }
        const __m512d qu = dot8(wu, wu), qv = dot8(wv, wv);
        const __m512d lu = _mm512_maskz_sqrt_pd(__mmask8(0xFF), qu), lv = _mm512_maskz_sqrt_pd(__mmask8(0xFF), qv);
        const __mmask8 valid = live & _mm512_cmp_pd_mask(lu, tiny, _CMP_GT_OQ) & _mm512_cmp_pd_mask(lv, tiny, _CMP_GT_OQ);
        const __m512d eu = _mm512_div_pd(_mm512_sub_pd(qu, one), _mm512_add_pd(lu, one));
        const __m512d ev = _mm512_div_pd(_mm512_sub_pd(qv, one), _mm512_add_pd(lv, one));
        const __m512d gamma = dot8(wu, wv);
        const __m512d sigma_u = _mm512_add_pd(_mm512_mul_pd(c11, eu), _mm512_mul_pd(c12, ev));
        const __m512d sigma_v = _mm512_add_pd(_mm512_mul_pd(c22, ev), _mm512_mul_pd(c12, eu));
        const __m512d tau = _mm512_mul_pd(c66, gamma);
        const __m512d a = _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(area), _mm512_set1_epi64(INT64_MIN)));  // -A
        const __m512d su = _mm512_maskz_div_pd(valid, sigma_u, lu), sv = _mm512_maskz_div_pd(valid, sigma_v, lv);
        for (int axis = 0; axis < 3; ++axis) {
            const __m512d pu = _mm512_mul_pd(a, _mm512_add_pd(_mm512_mul_pd(su, wu[axis]), _mm512_mul_pd(tau, wv[axis])));
            const __m512d pv = _mm512_mul_pd(a, _mm512_add_pd(_mm512_mul_pd(sv, wv[axis]), _mm512_mul_pd(tau, wu[axis])));
            // Interleaved in double (p_u of lane l at 2 l, p_v at 2 l + 1), then rounded: two runs of eight floats.
            const __m512d u = _mm512_maskz_mov_pd(valid, pu), w = _mm512_maskz_mov_pd(valid, pv);
            const __m256 lo = _mm512_maskz_cvtpd_ps(__mmask8(0xFF), _mm512_permutex2var_pd(u, low, w));
            const __m256 hi = _mm512_maskz_cvtpd_ps(__mmask8(0xFF), _mm512_permutex2var_pd(u, high, w));
            _mm256_mask_storeu_ps(out[axis] + base + 2 * m, static_cast<__mmask8>(pairs & 0xFF), lo);
            _mm256_mask_storeu_ps(out[axis] + base + 2 * m + 8, static_cast<__mmask8>(pairs >> 8), hi);
        }
    }
}

}  // namespace

// Particles [first, last) (whole blocks of kLanes, the last one maybe short) add their terms, sixteen at a time
// in lanes: each lane's terms in its list order, with the scalar loop's multiply and add (no fused
// multiply-add), so the same bits.
__attribute__((target("avx512f,avx512vl,avx2,fma"))) static void sum_avx512(const ElementGather& g, std::size_t first,
                                                                             std::size_t last, Vec3Array& force) {
    const float* fx = g.element_force.x.data();
    const float* fy = g.element_force.y.data();
    const float* fz = g.element_force.z.data();
    for (std::size_t i0 = first; i0 < last; i0 += kLanes) {
        const std::size_t b = i0 / kLanes;
        const __mmask16 live = last - i0 >= kLanes ? __mmask16(0xFFFF) : __mmask16((1u << (last - i0)) - 1u);
        const __m512i terms = _mm512_maskz_loadu_epi32(live, &g.lane_terms[i0]);
        __m512 sx = _mm512_maskz_loadu_ps(live, &force.x[i0]);
        __m512 sy = _mm512_maskz_loadu_ps(live, &force.y[i0]);
        __m512 sz = _mm512_maskz_loadu_ps(live, &force.z[i0]);
        const std::uint32_t longest = (g.lanes_begin[b + 1] - g.lanes_begin[b]) / static_cast<std::uint32_t>(kLanes);
        for (std::uint32_t t = 0; t < longest; ++t) {
            const __mmask16 on = _mm512_mask_cmpgt_epu32_mask(live, terms, _mm512_set1_epi32(static_cast<int>(t)));
            const std::size_t at = g.lanes_begin[b] + t * kLanes;
            const __m512i from = _mm512_loadu_si512(&g.lane_source[at]);
            const __m512 c = _mm512_loadu_ps(&g.lane_coefficient[at]);
            const __m512 zero = _mm512_setzero_ps();
            sx = _mm512_mask_add_ps(sx, on, sx, _mm512_mul_ps(c, _mm512_mask_i32gather_ps(zero, on, from, fx, 4)));
            sy = _mm512_mask_add_ps(sy, on, sy, _mm512_mul_ps(c, _mm512_mask_i32gather_ps(zero, on, from, fy, 4)));
            sz = _mm512_mask_add_ps(sz, on, sz, _mm512_mul_ps(c, _mm512_mask_i32gather_ps(zero, on, from, fz, 4)));
        }
        _mm512_mask_storeu_ps(&force.x[i0], live, sx);
        _mm512_mask_storeu_ps(&force.y[i0], live, sy);
        _mm512_mask_storeu_ps(&force.z[i0], live, sz);
    }
}

void gather_spring_forces(const Topology& topology, ElementGather& g, const DVec3Array& position,
                          const SpringSettings& springs, Vec3Array& force, int threads) {
    using Vec = glm::vec3;
    WorkTeam& team = WorkTeam::shared();
    const int spring_pieces = WorkTeam::pieces(g.springs, kPiece), hinge_pieces = WorkTeam::pieces(g.hinges, kPiece);
    const int membrane_pieces = WorkTeam::pieces(g.membranes, kPiece), corner_pieces = WorkTeam::pieces(g.corners, kPiece);
    const MembraneTensor tensor = membrane_tensor(springs);
    const double gaussian = gaussian_coefficient(topology.gaussian, springs);
    // Each element's force, as accumulate_spring_forces computes it (an element it skips gets zero, which adds
    // nothing: a sum that starts at +0 never becomes -0).
    const bool wide = FastSolver::kernel() == FastKernel::Avx512;
    const bool curved = has_mesh_curves(springs);  // springs with curves in the scalar loop (its hinge sums)
    team.run(threads, spring_pieces + hinge_pieces + membrane_pieces + corner_pieces, [&](int piece, int) {
        if (piece >= spring_pieces + hinge_pieces + membrane_pieces) {  // rim corners (gaussian_curvature.hpp)
            const std::size_t first = static_cast<std::size_t>(piece - spring_pieces - hinge_pieces - membrane_pieces) * kPiece;
            const std::size_t last = std::min(g.corners, first + kPiece);
            const std::size_t slot = g.springs + g.hinges + 2 * g.membranes + 3 * first;
            if (gaussian == 0.0) {
                for (std::size_t k = slot; k < slot + 3 * (last - first); ++k) g.element_force.set(k, Vec(0.0f));
                return;
            }
            gaussian_corner_forces(topology.gaussian, position, gaussian, first, last, g.element_force, slot);
            return;
        }
        if (piece < spring_pieces) {
            const std::size_t first = static_cast<std::size_t>(piece) * kPiece, last = std::min(g.springs, first + kPiece);
            if (wide && !curved) {
                springs_avx512(g, position, springs, first, last);
                return;
            }
            for (std::size_t j = first; j < last; ++j) {
                const Spring& s = topology.springs[j];
                const float ks = stiffness_of(springs, s);
                Vec f(0.0f);
                const Vec d(position.get(s.b) - position.get(s.a));
                const float rest = s.rest_length;
                if (ks != 0.0f) {
                    if (rest == 0.0f) {
                        f = ks * d;
                    } else if (const float length = glm::length(d); length > 1e-12f) {
                        f = (ks * curve_of(springs, s).stretch_term(length - rest, rest) / length) * d;
                    }
                }
                g.element_force.set(j, f);
            }
            return;
        }
        if (piece >= spring_pieces + hinge_pieces) {  // membranes: p_u and p_v (membrane.hpp), in the scalar order
            const std::size_t first = static_cast<std::size_t>(piece - spring_pieces - hinge_pieces) * kPiece;
            const std::size_t last = std::min(g.membranes, first + kPiece);
            const std::size_t base = g.springs + g.hinges;
            if (wide && springs.membrane_curve[0].knots == 0 && springs.membrane_curve[1].knots == 0) {
                membranes_avx512(g, position, tensor, first, last);
                return;
            }
            for (std::size_t m = first; m < last; ++m) {
                Vec pu(0.0f), pv(0.0f);  // left 0 for a collapsed triangle
                membrane_forces(position, topology.membranes[m], tensor, springs, pu, pv);
                g.element_force.set(base + 2 * m, pu);
                g.element_force.set(base + 2 * m + 1, pv);
            }
            return;
        }
        const std::size_t first = static_cast<std::size_t>(piece - spring_pieces) * kPiece;
        const std::size_t last = std::min(g.hinges, first + kPiece);
        if (wide) {
            hinges_avx512(g, position, springs, first, last);
            return;
        }
        for (std::size_t h = first; h < last; ++h) {
            const Hinge& hinge = topology.hinges[h];
            const float kh = stiffness_of(springs, hinge);
            g.element_force.set(g.springs + h, kh == 0.0f ? Vec(0.0f) : kh * Vec(hinge_difference(position, hinge)));
        }
    });
    // Each particle's sum, in list order: sixteen particles at a time with the AVX-512 kernel (FastSolver's
    // choice, so the tests run every kernel the CPU has), else one at a time.
    const std::size_t n = g.begin.size() - 1;
    team.run_pieces(threads, n, kPiece, [&](std::size_t first, std::size_t last) {
        if (wide) {
            sum_avx512(g, first, last, force);
            return;
        }
        for (std::size_t i = first; i < last; ++i) {
            Vec sum = force.get(i);
            for (std::uint32_t k = g.begin[i]; k < g.begin[i + 1]; ++k) sum += g.coefficient[k] * g.element_force.get(g.source[k]);
            force.set(i, sum);
        }
    });
}

}  // namespace clothsim
