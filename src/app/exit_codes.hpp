// Exit codes of the clothsim executable, for the app, the headless runs and the command line alike.
#pragma once

namespace clothsim {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 2;    // a bad flag, scene or output path; no display or OpenGL 3.3; a
                                           // missing shader or texture
inline constexpr int kExitBlowUp = 3;      // the simulation blew up: a step failed the guard's check (non-finite
                                           // positions, strain or an energy jump beyond GuardSettings in
                                           // clothsim/stability.hpp), or --guard ran out of retries
inline constexpr int kExitGlError = 4;
inline constexpr int kExitNotSettled = 5;  // --settle ran its whole time (--duration, --steps or 30 s) without the
                                           // residual falling below the tolerance     // an OpenGL error in a scripted (--frames) run

}  // namespace clothsim
