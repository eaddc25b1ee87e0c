// Cloth meshes the project makes itself (cloth.mesh; clothsim-make-meshes writes them to assets/meshes): rows of
// points about one edge length apart, neighbouring rows zipped into triangles, every boundary point on the
// shape's outline (boundary-conforming: no staircase rim), wound as the grid's triangles (normal -y when flat).
#pragma once

#include "clothsim/triangle_mesh.hpp"

namespace clothsim {

// A disc of `radius` in the x-z plane about the origin: the centre (vertex 0), then ring k = 1 .. rings of 6k
// points at radius k / rings, from +x. Ring k holds vertices 1 + 3 k (k - 1) .. 3 k (k + 1).
TriangleMesh cloth_disc(double radius, int rings);

// A flat elliptical annulus in the x-z plane: rings from the ellipse of semi-axes (inner_a along x, inner_b
// along z) outwards by `width`, each with points about `edge` apart. The inner ring comes first (vertex 0 on +x):
// a circle skirt's waist.
TriangleMesh cloth_annulus(double inner_a, double inner_b, double width, double edge);
// How many points the inner ring of cloth_annulus has.
int annulus_inner_count(double inner_a, double inner_b, double edge);

// The part of a cone about the y axis behind it (-z): rows from a ring of `top_radius` at y = 0 down to one of
// `bottom_radius` at y = -height, each an arc of `sweep_degrees` centred on -z with points about `edge` apart.
// The top row comes first: a cape's collar.
TriangleMesh cloth_cone_back(double top_radius, double bottom_radius, double height, double edge, double sweep_degrees);
int cone_back_top_count(double top_radius, double edge, double sweep_degrees);

// A tabard: two panels, front and back, `width` across (x), sewn together along the shoulder seam (the line
// x in [-width/2, width/2], y = z = 0) either side of a square neck opening. Along its length s (s > 0 down the
// front, s < 0 down the back, measured on the cloth from the seam) the cloth runs over the shoulders on a half
// cylinder of radius `yoke_radius` about the x axis at y = -yoke_radius, then straight down at z = +-yoke_radius
// to its hems at s = front_length and s = -back_length. The neck is the hole |x| < neck_half_width,
// -neck_back < s < neck_front. Rows of points across at each s, the seam, the neck's edges and the neck's sides
// among them; the back hem's row comes first.
struct TabardPattern {
    double width = 0.40;
    double front_length = 0.75;
    double back_length = 0.70;
    double yoke_radius = 0.14;
    double neck_half_width = 0.09;
    double neck_front = 0.08;
    double neck_back = 0.07;
    double edge = 0.025;
};
TriangleMesh cloth_tabard(const TabardPattern& pattern);
// The point of the tabard at (x, s) as cloth_tabard places it.
glm::dvec3 tabard_point(const TabardPattern& pattern, double x, double s);

}  // namespace clothsim
