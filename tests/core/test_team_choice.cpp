// TeamChoice (src/core/integrators/team_choice.hpp): the faster of a team and one thread, chosen while it runs.
#include "integrators/team_choice.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <random>

using namespace clothsim;

TEST_CASE("team choice: uses the faster of team and one thread, probing the other less while it loses") {
    using std::chrono::microseconds;
    TeamChoice choice;
    // Runs substeps with the given costs; returns how many ran the choice not currently preferred.
    auto run = [&](int substeps, int team_us, int single_us) {
        int other = 0;
        for (int i = 0; i < substeps; ++i) {
            const bool single = choice.next_is_single();
            other += single != choice.single();
            choice.record(single, microseconds(single ? single_us : team_us));
        }
        return other;
    };
    // A healthy team: one thread loses every probe (each about kProbeUs long), and the waits grow (4, then at
    // least the probe's cost over kProbeShare, doubling up to 4096), so the probes take at most a few percent
    // of 8000 substeps' time.
    const int probed = run(8000, 100, 170);
    CHECK_FALSE(choice.single());
    CHECK(probed > 0);
    CHECK(probed * 170.0 <= 2.5 * TeamChoice::kProbeShare * (8000 - probed) * 100.0);
    // The team is starved by another process: one thread wins at the next probe.
    run(8192, 5000, 170);
    CHECK(choice.single());
    // The core is free again: a probe of the team finds it faster.
    run(8192, 100, 170);
    CHECK_FALSE(choice.single());
}

TEST_CASE("team choice: a preempted substep now and then does not give up a faster team, a team slow on average "
          "is given up") {
    using std::chrono::microseconds;
    TeamChoice choice;
    // Runs substeps whose cost the function of (substep, single) gives; returns how many ran one thread.
    int substep = 0;
    auto run = [&](int substeps, auto cost_us) {
        int singles = 0;
        for (int i = 0; i < substeps; ++i, ++substep) {
            const bool single = choice.next_is_single();
            singles += single;
            choice.record(single, microseconds(cost_us(substep, single)));
        }
        return singles;
    };
    // 256 x 256 on this machine: the team 120 us a substep, one thread 240. Every 300th team substep is
    // preempted for a scheduler slice (4 ms): the team's mean is 133 us, still the faster. Only the probes
    // run one thread (a fixed weight of a quarter made the team lose for 64 substeps after each such one).
    const int singles = run(20000, [](int i, bool single) { return single ? 240 : (i % 300 == 299 ? 4000 : 120); });
    CHECK_FALSE(choice.single());
    CHECK(singles * 240.0 <= 2.5 * TeamChoice::kProbeShare * (20000 - singles) * 133.0);
    // A team preempted every 10th substep for 4 ms is slower on average (508 us) than one thread: given up.
    // Its probes, two substeps counted, mostly miss the preemption and win; the team then loses again over
    // its window, and each such round doubles the wait, so the team runs few of the substeps.
    const int phase = 20000;
    const int singles_while_preempted = run(phase, [](int i, bool single) { return single ? 240 : (i % 10 == 9 ? 4000 : 120); });
    CHECK(choice.single());
    CHECK(phase - singles_while_preempted < phase / 20);
    // Free again, but the first probe that comes is preempted: it ends there and loses, and a later probe
    // takes the team back.
    int in_a_row = 0;  // team substeps in a row
    bool preempted = false;
    run(20000, [&](int, bool single) {
        in_a_row = single ? 0 : in_a_row + 1;
        if (!single && in_a_row == TeamChoice::kProbeLength && !preempted) {
            preempted = true;
            return 4000;
        }
        return single ? 240 : 120;
    });
    CHECK(preempted);
    CHECK_FALSE(choice.single());
}

TEST_CASE("team choice: a small cloth's team preempted now and then stays in use when it is faster on average") {
    using std::chrono::nanoseconds;
    // 64 x 64 Verlet on a 2-vCPU machine: the team 51 us a substep, one thread 67 (a margin of a third). One
    // substep in 400, at random, is preempted for a scheduler slice (4 ms; half as often on one thread, which
    // leaves a core free): the team's mean is 61 us, one thread's 72. Two slices within a frame made a
    // one-frame mean of the team pass one thread's measure, which then ran until the next probe: 6-10% over the
    // team's time on these five seeds. The choice's time is within 5% of the team's on average.
    double worst = 0.0;
    for (unsigned seed = 0; seed < 5; ++seed) {
        TeamChoice choice;
        std::mt19937 random(seed);
        double spent_us = 0.0;
        const int substeps = 200000;
        for (int i = 0; i < substeps; ++i) {
            const bool single = choice.next_is_single();
            const double us = (single ? 67.0 : 51.0) + (random() % 400 == 0 ? (single ? 2000.0 : 4000.0) : 0.0);
            spent_us += us;
            choice.record(single, nanoseconds(static_cast<long long>(us * 1e3)));
        }
        worst = std::max(worst, spent_us / substeps / 61.0);
    }
    CHECK(worst < 1.05);
}

TEST_CASE("team choice: both are measured within the first frame") {
    using std::chrono::microseconds;
    TeamChoice choice;
    // One thread 3x faster (a small cloth): taken within the first frame (16.7 ms of substeps), so that frame
    // pays little: the team runs until the first probe, and one probe of its own (kProbeUs and its uncounted
    // first substep) after one thread has won.
    int team_substeps = 0;
    for (double spent_us = 0.0; spent_us < 16667.0;) {
        const bool single = choice.next_is_single();
        team_substeps += !single;
        spent_us += single ? 100 : 300;
        choice.record(single, microseconds(single ? 100 : 300));
    }
    CHECK(choice.single());
    CHECK(team_substeps <= TeamChoice::kFirstProbe + 1 + static_cast<int>(TeamChoice::kProbeUs / 300.0) + 1);
}

TEST_CASE("team choice: a team a hundred times slower than one thread costs a few percent in probes, not seconds") {
    using std::chrono::microseconds;
    TeamChoice choice;
    // A heavily loaded machine: each team substep waits for a descheduled thread (20 ms), one thread takes
    // 0.2 ms. Probes of the team end at their first counted substep (kAbandon), and wait at least their cost over
    // kProbeShare, so over 50000 substeps the team's substeps take a few percent of the time.
    double team_us = 0.0, single_us = 0.0;
    for (int i = 0; i < 50000; ++i) {
        const bool single = choice.next_is_single();
        const double us = single ? 200.0 : 20000.0;
        (single ? single_us : team_us) += us;
        choice.record(single, microseconds(static_cast<long long>(us)));
    }
    CHECK(choice.single());
    INFO("team " << team_us / 1e3 << " ms, one thread " << single_us / 1e3 << " ms");
    CHECK(team_us < 0.05 * (team_us + single_us));
}

TEST_CASE("team choice: a choice that becomes slower than the other's last measure is left within a window, "
          "not after the long wait") {
    using std::chrono::microseconds;
    TeamChoice choice;
    auto run = [&](int substeps, int team_us, int single_us) {
        int singles = 0;
        for (int i = 0; i < substeps; ++i) {
            const bool single = choice.next_is_single();
            singles += single;
            choice.record(single, microseconds(single ? single_us : team_us));
        }
        return singles;
    };
    // One thread is faster for long enough that the wait reaches its longest.
    run(20000, 400, 200);
    REQUIRE(choice.single());
    // Then one thread becomes 10x slower (another program takes its core, the team's pieces go to the free
    // one): its mean passes the team's last measure within a window and the team is taken, within a few
    // hundred substeps, not after the 4096 of the wait.
    int substeps = 0;
    while (choice.single() && substeps < 5000) {
        run(1, 400, 2000);
        ++substeps;
    }
    CHECK_FALSE(choice.single());
    CHECK(substeps < 300);
}
