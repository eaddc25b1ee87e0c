// TeamChoice: whether a threaded path's team (work_team.hpp) is faster than one thread right now.
//
// A team pays for handing out work and waiting for its last piece; on a small cloth, or with another program
// on one of the cores, one thread can be faster (docs/PERFORMANCE.md, "Threads under load"). With
// solver.threads = 0 the fast solver and XPBD's grid form therefore keep a running estimate of a substep's
// mean time with the team and with one thread over about the last frame, now and then run a few substeps the
// other way (a probe, timed on the fastest of its last two), and use whichever is faster. The first probe
// comes after kFirstProbe substeps, so both are measured within the first frame. A probe that loses doubles
// the wait before the next one (up to kLongestWait substeps), and the wait is never shorter than what keeps
// the probes' cost under kProbeShare of the time (a probe that cost 100 substeps' worth waits 100 /
// kProbeShare); a probe whose counted substep takes kAbandon times the current choice's mean ends there. So a team
// that stays slow costs little to keep checking. Results are bit-identical for any thread count
// (fast_solver.hpp, grid_xpbd.hpp), so switching never changes the cloth.
#pragma once

#include <algorithm>
#include <chrono>

namespace clothsim {

class TeamChoice {
public:
    static constexpr int kFirstProbe = 4, kLongestWait = 4096;  // substeps between probes
    static constexpr double kProbeShare = 0.02;  // the most of the time the probes may take
    static constexpr double kAbandon = 4.0;      // a counted probe substep this many times the current mean ends it
    static constexpr int kProbeLength = 3;       // the fewest substeps a probe runs the other way
    static constexpr double kProbeUs = 2000.0;   // ... and the least time its counted substeps take
    static_assert(kProbeLength >= 2, "a probe counts its substeps after the first");

    // Whether the next substep should run on one thread.
    bool next_is_single() {
        if (!probing_ && ++since_probe_ >= wait_) {
            since_probe_ = 0;
            probing_ = true;
            probe_substeps_ = 0;
        }
        return probing_ ? !single_ : single_;
    }
    // Records how long a substep took with one thread (`single`) or the team, and chooses again.
    void record(bool single, std::chrono::steady_clock::duration elapsed) {
        const double us = std::chrono::duration<double, std::micro>(elapsed).count();
        if (!started_) {  // the first substep starts the team's threads: no measure of either choice
            started_ = true;
            return;
        }
        const bool probing = probing_;
        if (probing) {
            probe_us_ += us;
            const double current = single ? team_us_ : single_us_;  // the choice in use (the probe runs the other)
            if (++probe_substeps_ > 1) {
                // A probe's first substep moves the data into the other cores' caches (and wakes the helpers)
                // and is not counted. The others are counted for at least kProbeUs: their mean is what the
                // choice in use is measured by too (a mean over time), so neither side is favoured by the
                // spread of substep times a shared core gives. A counted substep far slower than the choice in
                // use ends the probe.
                counted_us_ += us;
                ++counted_;
                const bool long_enough = probe_substeps_ >= kProbeLength && counted_us_ >= kProbeUs;
                if (!long_enough && !(current > 0.0 && us > kAbandon * current)) return;
            } else {
                return;
            }
            probing_ = false;
        }
        const double probe_cost_us = probe_us_;
        probe_us_ = 0.0;
        double& estimate = single ? single_us_ : team_us_;
        if (probing) {
            // A probe replaces the other choice's estimate, which is as old as the last probe (the load it saw
            // may be gone).
            estimate = counted_us_ / counted_;
            counted_us_ = 0.0;
            counted_ = 0;
        } else if (estimate < 0.0) {
            estimate = us;
            recent_us_ = us;
        } else {
            // The mean substep of about the last kWindowUs of the choice in use (an exponential average, each
            // substep weighted by its share of the window): what the choice costs over several frames. A shared
            // machine's occasional preempted substep (a scheduler slice, milliseconds) moves it by that
            // substep's share of the window only, so it does not make a faster team look slower (with a
            // one-frame window, two slices close together made a 64 x 64 team look slower than one thread,
            // which then ran until the next probe: a quarter to half of the substeps, 1.05-1.17x the team's
            // time). A choice slowed on average (a core taken by another process) overtakes the other within
            // about a window, and within a frame when it has become kJump times slower than the other's
            // measure: the mean of the last kRecentUs says so, and becomes the choice's estimate.
            estimate += std::min(kMaxWeight, estimate / kWindowUs) * (us - estimate);
            recent_us_ += std::min(kMaxWeight, recent_us_ / kRecentUs) * (us - recent_us_);
            const double other = single ? team_us_ : single_us_;
            if (other > 0.0 && recent_us_ > kJump * other) estimate = std::max(estimate, recent_us_);
        }
        if (single_us_ < 0.0 || team_us_ < 0.0) return;
        const bool was = single_;
        single_ = single_us_ < team_us_;
        if (single_ != was) recent_us_ = single_ ? single_us_ : team_us_;
        // The wait before the next probe doubles when a probe loses, and when the choice a probe won turns out
        // slower over its window after all (a team preempted now and then wins short probes and loses on
        // average): either way the other choice was not worth trying so soon.
        if (probing ? single_ == was : single_ != was) wait_ = std::max(wait_, std::min(2 * wait_, kLongestWait));
        if (probing) {
            // The probes' share of the time: the next one waits at least its cost over kProbeShare.
            const double mean = single_ ? single_us_ : team_us_;
            const double cost_in_substeps = mean > 0.0 ? probe_cost_us / mean : 0.0;
            if (single_ == was) wait_ = std::max(wait_, static_cast<int>(std::min(1e9, cost_in_substeps / kProbeShare)));
        }
    }
    bool single() const { return single_; }
    void reset() { *this = TeamChoice{}; }

private:
    static constexpr double kWindowUs = 128000.0;  // about eight frames
    static constexpr double kRecentUs = 16000.0;   // about a frame
    static constexpr double kJump = 1.5;           // a recent mean this many times the other's leaves at once
    static constexpr double kMaxWeight = 0.25;
    bool started_ = false;
    bool single_ = false;
    bool probing_ = false;
    int probe_substeps_ = 0;  // substeps the probe under way has run
    int since_probe_ = 0;
    int wait_ = kFirstProbe;
    double single_us_ = -1.0, team_us_ = -1.0;
    double recent_us_ = -1.0;  // the choice in use: its mean over the last kRecentUs
    double counted_us_ = 0.0;  // the probe under way: the time of its counted substeps
    int counted_ = 0;          // ... and their number
    double probe_us_ = 0.0;    // the time the probe under way has taken
};

}  // namespace clothsim
