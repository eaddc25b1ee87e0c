// The elastic elements of a cloth: Hooke springs between two particles, and bends, the quadratic bending
// of three consecutive particles on a grid line. Their stiffness lives in SpringSettings, by kind and axis,
// so that changing it applies live, without rebuilding the element lists.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace clothsim {

enum class SpringKind : std::uint8_t {
    Structural = 0,  // horizontal and vertical neighbours
    Shear = 1,       // both diagonals of a grid cell
    Bending = 2,     // skip-one springs two apart along rows and columns, or bends (below)
};
inline constexpr int kSpringKindCount = 3;

const char* to_string(SpringKind kind);

// The direction an element runs in on the grid: along u_axis (a row), along v_axis (a column), or across a
// cell. Anisotropic fabric (warp and weft) has a stiffness per axis.
enum class Axis : std::uint8_t { U = 0, V = 1, Diagonal = 2 };

// A Hooke spring: F_a = k w (|d| - L0) d/|d| with d = x_b - x_a, k from the settings (kind, axis), w the
// spring's weight. Topology only: which particles, how long at rest, which stiffness.
struct Spring {
    std::uint32_t a = 0;
    std::uint32_t b = 0;
    float rest_length = 0.0f;  // m
    SpringKind kind = SpringKind::Structural;
    Axis axis = Axis::U;
    // A mesh cloth's material spring: 1 + cos^2 of its rest direction's angle to u_axis in kWarpLevels-ths
    // (rounded), which picks its stretch curve, a blend of the two directions' (SpringSettings::mesh_curve,
    // stretch_curve.hpp); 0 on a grid and in the per-spring form, whose structural springs take their axis's.
    std::uint8_t warp_level = 0;
    // The share of the cells around the spring the cloth has: 1 inside, 0.5 for a structural spring on the
    // cloth's edge, which borders one cell instead of two (material form; always 1 in the per-spring form).
    // A power of two, so k w is exact and every solver path rounds alike.
    float weight = 1.0f;
};

// A bend: three consecutive particles a, m, b on a grid line, with the quadratic isometric bending energy
// E = 0.5 k w |x_a - 2 x_m + x_b|^2 (Bergou, Wardetzky, Harmon, Zorin & Grinspun 2006, "A quadratic bending
// model for inextensible surfaces", on a regular grid, where the discrete Laplacian along a line is the
// second difference). For an inextensible line bent to curvature kappa, |x_a - 2 x_m + x_b| = h^2 kappa,
// so k = B / h^2 per unit of the line's width gives the plate energy 0.5 B kappa^2 per area: the flexural
// rigidity B (N m) is the same at every grid spacing. Forces are linear: F_a = F_b = -k w d, F_m = 2 k w d.
struct Bend {
    std::uint32_t a = 0;
    std::uint32_t m = 0;
    std::uint32_t b = 0;
    Axis axis = Axis::U;
    float weight = 1.0f;  // 0.5 on the cloth's edge rows and columns, which carry half a line's width
};

// A hinge: the bending across an interior edge (v[0], v[1]) of a triangle mesh cloth, between its two
// triangles (v[0], v[1], v[2]) and (v[0], v[1], v[3]), with Bergou et al. 2006's quadratic energy (the same
// paper as Bend; Wardetzky, Bergou, Harmon, Zorin & Grinspun 2007, "Discrete quadratic curvature energies"):
// E = 0.5 k |sum_i c_i x_i|^2 with the rest shape's cotangent weights
//   c = (cot b_0 + cot b_1, cot a_0 + cot a_1, -(cot a_0 + cot b_0), -(cot a_1 + cot b_1)),
// a_t and b_t the angles of triangle t at v[0] and v[1]. The weights sum to 0 and sum_i c_i x_i vanishes for
// the flat rest shape, so the energy is 0 there and for any rigid motion of it; for a dihedral angle theta,
// |sum_i c_i x_i| = 2 |e| sin(theta / 2). k = B / (A_0 + A_1) gives a cylinder of curvature kappa the plate
// energy of about 0.5 B kappa^2 per area (docs/MESH_CLOTH.md measures it; Bergou et al.'s 3 / (A_0 + A_1) with
// this stencil stores three times that). k = bending.x weight_u + bending.y weight_v (held at 0 or more): in the
// per-spring form the weights are sin^2 and cos^2 of the rest edge's angle to u_axis (an edge along u bends along
// v); in the material form (1/m^2) they are calibrated so that the mesh bent along u stores bending.x and along v
// bending.y (cloth_mesh.cpp, calibrate_hinges), and a share may be negative.
struct Hinge {
    std::array<std::uint32_t, 4> v{};
    std::array<float, 4> c{};
    float weight_u = 0.0f;
    float weight_v = 0.0f;
};

// A constant-strain membrane triangle of a mesh cloth (cloth.membrane = "triangles"): the material's
// orthotropic plane-stress tensor on one triangle, instead of springs on its edges. With x_i its corners,
// w_u = sum_i bu_i x_i and w_v = sum_i bv_i x_i are the deformed images of the rest triangle's unit warp (u)
// and weft (v) directions (the columns of the deformation gradient F = D_s D_m^-1 in the triangle's rest frame),
// and the strains are Baraff & Witkin 1998's conditions ("Large steps in cloth simulation", section 4.2):
// e_u = |w_u| - 1, e_v = |w_v| - 1, the shear gamma = w_u . w_v. The energy is
//   A (C11 U_u(e_u) + C22 U_v(e_v) + C12 e_u e_v + 0.5 C66 gamma^2),
// U(e) = 0.5 e^2 (or a stretch curve's energy term), A the rest area, C the tensor of the material
// (membrane.hpp: the grid's own continuum tensor, so a uniform strain stores what the grid's cells store). A
// uniform strain of any triangulation is in equilibrium (the constant-strain patch test), which the edge springs
// of an irregular mesh are not. bu and bv sum to 0 over the corners; bu_0 = -(bu_1 + bu_2) in double, rounded.
// The Gaussian-curvature term of a flat mesh cloth's bending (model/gaussian_curvature.hpp). A plate's bending
// energy is 0.5 (B_11 k_11^2 + 2 B_12 k_11 k_22 + B_22 k_22^2 + 4 B_66 k_12^2) in its curvatures k; the hinges'
// sum stores some B_12 > 0 that depends on the triangulation (a bending Poisson ratio of about 1/3 on
// equilateral triangles), while a woven fabric, as the grid's row and column bends, has B_12 = 0. Since
// k_11 k_22 - k_12^2 is the Gaussian curvature K, the energy -B_12 integral(K dA) takes the coupling out, and
// by the discrete Gauss-Bonnet theorem it is a sum over the rim alone: with phi the triangles' corner angles,
//   E = c (pi T - 2 pi N_interior - sum over rim corners of phi),
// T the triangles, N_interior the vertices off the rim, c = B_12 = bending.x weight_u + bending.y weight_v.
// E is 0 at every flat shape. Built only for a rest shape whose hinges are all flat.
struct GaussianCurvature {
    std::vector<std::array<std::uint32_t, 3>> rim_corners;  // (a rim vertex, the triangle's next, its previous)
    float weight_u = 0.0f, weight_v = 0.0f;  // B_12 per unit bending.x, per unit bending.y
    double offset = 0.0;                      // pi T - 2 pi N_interior
};

struct Membrane {
    std::array<std::uint32_t, 3> v{};
    std::array<float, 3> bu{}, bv{};  // 1/m
    float area = 0.0f;                // m^2
};

}  // namespace clothsim
