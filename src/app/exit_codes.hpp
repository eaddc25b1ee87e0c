// Exit codes of the clothsim executable, for the app, the headless runs and the command line alike.
#pragma once

namespace clothsim {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 2;    // a bad flag, scene or output path; no display or OpenGL 3.3; a
                                           // missing shader or texture
inline constexpr int kExitNonFinite = 3;   // the simulation became non-finite (or the guard gave up)
inline constexpr int kExitGlError = 4;     // an OpenGL error in a scripted (--frames) run

}  // namespace clothsim
