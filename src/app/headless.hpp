// Headless runs: simulate a scene without a window and report on stdout (text or one JSON object).
#pragma once

#include "exit_codes.hpp"

#include "clothsim/settings.hpp"

#include <optional>
#include <string>

namespace clothsim {

struct HeadlessOptions {
    std::optional<double> duration;  // s of simulated time (rounded to whole steps)
    std::optional<long long> steps;  // steps of integration.dt
    std::string trajectory;          // CSV path, empty for none
    long long every = 1;             // record the trajectory every K steps
    std::string obj;                 // OBJ path of the final mesh, empty for none
    bool obj_colliders = false;      // the OBJ holds the colliders too, each its own object
    bool json = false;
    float auto_substeps = 0.0f;      // > 0: pick integration.substeps so the substep is this fraction of dt_crit
    bool guard = false;              // roll back and double the substeps when a step blows up
    bool settle = false;             // settle to rest (settle.hpp) instead of running a set time
    double settle_tolerance = 0.01;  // with settle: the residual that counts as settled
};

int run_headless(const Scene& scene, const HeadlessOptions& options);

}  // namespace clothsim
