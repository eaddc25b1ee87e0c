// A user at the desktop app: the real clothsim executable in a real window on an X server of its own
// (Xvfb, so tests running side by side never share a pointer or a keyboard focus), driven with xdotool
// (keys, clicks, ctrl+clicks, drags) exactly as a user's hands would drive it. F12 screenshots show what the
// user sees at any moment. Nothing goes through a scripted flag except --quit-after, which ends the run.
#pragma once

#include "run_process.hpp"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace clothsim::test {

// The actions a session's script may use (bash functions, after the window has appeared; $wid is it):
//   key KEYS...          presses keys (xdotool names: space, r, w, F12, ctrl+a, Return)
//   type TEXT            types text into the focused field
//   click X Y            left click at window coordinates (pixels from the top-left)
//   ctrl_click X Y       the same with Ctrl held
//   drag X0 Y0 X1 Y1     left button down at (X0, Y0), moved to (X1, Y1), released
//   cut X0 Y0 X1 Y1      the same with the right button and Shift held (the knife)
//   alt_drag X0 Y0 X1 Y1 a left drag with Alt held (moves an object)
//   shot NAME            an F12 screenshot, saved as NAME (a PNG in the session's directory)
//   settle               waits until the app has drawn two frames after what came before (frame, twice)
//   frame                waits until the app has drawn a frame after what came before: F12 asks for a
//                        screenshot, which the app writes at the end of the frame that read the key, so the
//                        file's arrival is that frame (up to 60 s on a loaded machine); the file is removed
//   wait_for FILE        waits (up to 60 s) until FILE exists in the session's directory (a save)
//   title_has TEXT       waits (up to 60 s) until the window's title contains TEXT: an action whose effect
//                        takes longer than a few frames under load (a file opened through the dialog)
//   drop X Y FILE...     drops files at (X, Y) as a file manager does (XDND, tests/app/xdnd_drop.cpp)
//   quit                 presses Escape (the app's quit key) with the pointer over the 3D view
// Each action waits afterwards until the app has drawn frames with it: it waits for the frames, never for a
// fixed time, so a session passes on a loaded machine and in the ASan build alike.
inline const char* kSessionFunctions = R"sh(
frame() {
  rm -f clothsim-*.png
  xdotool keydown F12; sleep 0.02; xdotool keyup F12
  for _ in $(seq 600); do ls clothsim-*.png >/dev/null 2>&1 && break; kill -0 $app 2>/dev/null || break; sleep 0.05; done
  rm -f clothsim-*.png
}
settle() { frame; frame; }
wait_for() { for _ in $(seq 600); do [ -e "$1" ] && break; sleep 0.1; done; settle; }
# Held for 0.15 s as a hand holds a key: ImGui 1.86's widgets see the key state once a frame, so a press and
# release within one slow frame (xdotool's plain "key") would never reach a text field.
key() { for k in "$@"; do xdotool keydown "$k"; sleep 0.15; xdotool keyup "$k"; sleep 0.05; done; settle; }
type() { xdotool type --delay 40 "$1"; settle; }
at() { xdotool mousemove --window "$wid" "$1" "$2"; sleep 0.2; }
click() { at "$1" "$2"; xdotool click 1; settle; }
ctrl_click() { at "$1" "$2"; xdotool keydown ctrl; sleep 0.2; xdotool click 1; sleep 0.2; xdotool keyup ctrl; settle; }
drag() { at "$1" "$2"; xdotool mousedown 1; sleep 0.3; xdotool mousemove --window "$wid" "$3" "$4"; sleep 0.5;
         xdotool mouseup 1; settle; }
cut() { at "$1" "$2"; xdotool keydown shift; sleep 0.2; xdotool mousedown 3; sleep 0.3;
        xdotool mousemove --window "$wid" "$3" "$4"; sleep 0.5; xdotool mouseup 3; sleep 0.2; xdotool keyup shift; settle; }
alt_drag() { at "$1" "$2"; xdotool keydown alt; sleep 0.2; xdotool mousedown 1; sleep 0.3;
             xdotool mousemove --window "$wid" "$3" "$4"; sleep 0.5; xdotool mouseup 1; sleep 0.2; xdotool keyup alt; settle; }
quit() { at 900 400; key Escape; }
title_has() { for _ in $(seq 600); do xdotool getwindowname "$wid" | grep -qF -- "$1" && break; sleep 0.1; done; }
drop() { local x="$1" y="$2"; shift 2; "$XDND_DROP" "$wid" "$x" "$y" "$@" || echo "drop: not taken" >&2; settle; }
shot() {
  rm -f clothsim-*.png
  xdotool keydown F12; sleep 0.02; xdotool keyup F12
  for _ in $(seq 600); do ls clothsim-*.png >/dev/null 2>&1 && break; sleep 0.05; done
  local png
  png=$(ls clothsim-*.png 2>/dev/null | head -n1)
  if [ -z "$png" ]; then echo "shot $1: no screenshot was written" >&2; return; fi
  mv "$png" "$1.partial"
  frame  # a later frame has been drawn: the app has written the PNG whole
  mv "$1.partial" "$1"
}
)sh";

// Runs `clothsim args...` in `dir` on a private X server, waits for its window, runs `actions` (lines of the
// functions above; end them with quit, or give the app --quit-after), then waits up to 60 s for the app to
// exit. The app's settings live in dir/config ($XDG_CONFIG_HOME), never the user's; its file dialog is the
// built-in browser (CLOTHSIM_FILE_DIALOG=imgui) unless `env` (shell assignments, e.g. "PATH=...") says
// otherwise. The result's code is the app's exit code; 90 when no window appeared in 60 s, 91 when no X server started,
// 92 when the app did not exit (it is killed).
inline RunResult run_user_session(const TempDir& dir, const std::vector<std::string>& args,
                                  const std::string& actions, const std::string& env = "") {
    std::string command = "env XDG_CONFIG_HOME=" + quote((dir / "config").string()) + " CLOTHSIM_FILE_DIALOG=imgui " + env +
                          " " + quote(CLOTHSIM_EXE);
    for (const std::string& a : args) command.append(" ").append(quote(a));
    const std::filesystem::path script = dir / "session.sh";
    std::ofstream(script) << "set -u\ncd " << quote(dir.path().string()) << "\n"
                          << R"sh(
XDND_DROP=)sh" << quote(CLOTHSIM_XDND_DROP) << R"sh(
# A private X server: -displayfd writes its display number once it accepts clients. The last session's
# file goes first: the shell truncates it only when the server's process starts, and a loop that read it
# before then found the old number's file non-empty and then read it empty (DISPLAY=":").
rm -f xvfb.display
Xvfb -displayfd 3 -screen 0 1280x720x24 -nolisten tcp -noreset 3>xvfb.display 2>xvfb.log &
xvfb=$!
trap 'kill $xvfb 2>/dev/null; wait $xvfb 2>/dev/null' EXIT
for _ in $(seq 200); do [ -s xvfb.display ] && break; sleep 0.05; done
[ -s xvfb.display ] || exit 91
export DISPLAY=":$(head -n1 xvfb.display)"
)sh" << kSessionFunctions << command << R"sh( >app.out 2>app.err &
app=$!
wid=""
for _ in $(seq 600); do
  wid=$(xdotool search --onlyvisible --name '^clothsim' 2>/dev/null | head -n1)
  [ -n "$wid" ] && break
  kill -0 $app 2>/dev/null || break
  sleep 0.1
done
if [ -z "$wid" ]; then
  if kill -0 $app 2>/dev/null; then kill -9 $app; wait $app; cat app.err >&2; exit 90; fi
  wait $app; code=$?; cat app.err >&2; exit $code
fi
at 900 400
settle
)sh" << actions << R"sh(
for _ in $(seq 600); do kill -0 $app 2>/dev/null || break; sleep 0.1; done
if kill -0 $app 2>/dev/null; then kill -9 $app; wait $app; cat app.err >&2; exit 92; fi
wait $app
code=$?
cat app.out
cat app.err >&2
exit $code
)sh";
    return run_process("timeout", {"300", "bash", script.string()});
}

// A stand-in zenity in dir/bin running the shell `body`, and the environment that puts it first on PATH.
// The app polls its answer whenever it comes, so a test does not depend on when a dialog has appeared.
inline std::string stand_in_zenity(const TempDir& dir, const std::string& body) {
    std::filesystem::create_directories(dir / "bin");
    std::ofstream(dir / "bin" / "zenity") << "#!/bin/sh\n" << body << "\n";
    std::filesystem::permissions(dir / "bin" / "zenity", std::filesystem::perms::owner_all);
    return "CLOTHSIM_FILE_DIALOG=auto PATH=" + quote((dir / "bin").string()) + ":\"$PATH\"";
}

// One that answers a save with the file it proposes, as a user pressing Save does.
inline std::string zenity_saving_as_proposed(const TempDir& dir) {
    return stand_in_zenity(dir, "for a in \"$@\"; do case \"$a\" in --filename=*) echo \"${a#--filename=}\"; exit 0 ;; esac; done\nexit 1");
}

}  // namespace clothsim::test
