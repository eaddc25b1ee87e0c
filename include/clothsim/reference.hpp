// Reference solutions and error norms for the accuracy study (docs/ACCURACY.md).
//
// The reference is the same scene, run by the same physics code (springs, wind, gravity, damping,
// collisions: the projection after each substep, or penalty contact forces, as colliders.contact says) in
// double precision with classical RK4, at a substep halved until halving it once more changes the final
// positions by less than `tolerance` of the cloth size. Only a smooth model has such a limit: projection
// contact's events and stick/slip switches change with the step (docs/ACCURACY.md).
#pragma once

#include "clothsim/mass_spring.hpp"
#include "clothsim/settings.hpp"

#include <glm/vec3.hpp>

#include <vector>

namespace clothsim {

// Final positions of `scene` after `duration` seconds of double-precision RK4 at substep `h` (adjusted
// so that a whole number of substeps ends exactly at `duration`).
std::vector<glm::dvec3> run_double_rk4(const Scene& scene, double duration, double h);

struct Reference {
    std::vector<glm::dvec3> positions;  // at `duration`
    double substep = 0.0;               // s: the step of `positions`
    double halving_change = 0.0;        // max |x(h) - x(h/2)| / cloth size at the last halving
    int halvings = 0;
    bool converged = false;             // halving_change < tolerance
};

// Halves the substep from `first_substep` (at most `max_halvings` times) until the change is below
// `tolerance` of the cloth size.
Reference reference_solution(const Scene& scene, double duration, double first_substep, double tolerance = 1e-9,
                             int max_halvings = 10);

struct ErrorNorms {
    double rms = 0.0;  // root mean square over particles of |x - x_ref| / size
    double max = 0.0;  // largest |x - x_ref| / size
};
ErrorNorms relative_error(const std::vector<glm::dvec3>& positions, const std::vector<glm::dvec3>& reference,
                          double size);
ErrorNorms relative_error(const MassSpring& sim, const std::vector<glm::dvec3>& reference, double size);

// The cloth size errors are relative to: its larger side (m).
double cloth_size(const Scene& scene);

}  // namespace clothsim
