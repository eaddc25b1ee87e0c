// WorkTeam (src/core/integrators/work_team.hpp): indexed jobs shared by the caller and helper threads.
#include "integrators/work_team.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

using namespace clothsim;

TEST_CASE("work team: every index runs exactly once, on a worker below the team size, for any team and count") {
    WorkTeam& team = WorkTeam::shared();
    for (int threads : {1, 2, 3, 4}) {
        for (int count : {0, 1, 2, 3, 7, 64, 1000}) {
            std::vector<std::atomic<int>> runs(static_cast<std::size_t>(count));
            std::atomic<int> bad_worker{0};
            team.run(threads, count, [&](int index, int worker) {
                runs[static_cast<std::size_t>(index)].fetch_add(1);
                if (worker < 0 || worker >= threads) bad_worker.fetch_add(1);
            });
            INFO(threads << " threads, " << count << " indices");
            CHECK(bad_worker.load() == 0);
            int once = 0;
            for (const std::atomic<int>& r : runs) once += r.load() == 1;
            CHECK(once == count);
        }
    }
}

TEST_CASE("work team: thousands of short jobs in a row each finish whole before the next starts") {
    // The jobs of a substep come microseconds apart: a helper still finishing one, or waking late, must never
    // run an index of the next job with the last job's work, or be counted in it.
    WorkTeam& team = WorkTeam::shared();
    std::vector<int> out(37);
    for (int job = 0; job < 5000; ++job) {
        team.run(2 + job % 3, static_cast<int>(out.size()), [&](int index, int) { out[static_cast<std::size_t>(index)] = job + index; });
        bool whole = true;
        for (std::size_t i = 0; i < out.size(); ++i) whole = whole && out[i] == job + static_cast<int>(i);
        if (!whole) FAIL("job " << job << " returned before all its indices had run");
    }
}

TEST_CASE("work team: a job started from inside a job, or from another thread while one runs, runs on its caller") {
    WorkTeam& team = WorkTeam::shared();
    std::atomic<int> inner{0};
    team.run(2, 4, [&](int, int) {
        const std::thread::id self = std::this_thread::get_id();
        bool same_thread = true;
        team.run(2, 8, [&](int, int worker) {
            same_thread = same_thread && std::this_thread::get_id() == self && worker == 0;
            inner.fetch_add(1);
        });
        CHECK(same_thread);
    });
    CHECK(inner.load() == 32);
    // Two threads, each with its own jobs: each finishes all of its indices.
    std::atomic<long long> sums[2] = {0, 0};
    auto caller = [&](int which) {
        for (int job = 0; job < 500; ++job) {
            team.run(2, 10, [&](int index, int) { sums[which].fetch_add(index); });
        }
    };
    std::thread a(caller, 0), b(caller, 1);
    a.join();
    b.join();
    CHECK(sums[0].load() == 500LL * 45);
    CHECK(sums[1].load() == 500LL * 45);
}

TEST_CASE("work team: a slow helper holds up one piece, not its share: the caller takes the rest") {
    // Every piece a helper runs takes 20 ms, as if it were descheduled in the middle of it (another program
    // holds its core). The pieces are handed out one at a time, so the caller runs all the others meanwhile
    // and the job ends once the helper's one piece does: not after a half share of 20 ms pieces.
    WorkTeam& team = WorkTeam::shared();
    std::atomic<int> by_caller{0}, by_helper{0};
    const std::thread::id self = std::this_thread::get_id();
    const auto start = std::chrono::steady_clock::now();
    team.run(2, 200, [&](int, int) {
        if (std::this_thread::get_id() == self) {
            by_caller.fetch_add(1);
        } else {
            by_helper.fetch_add(1);
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
    });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    INFO("the helper ran " << by_helper.load() << " pieces; the job took " << seconds << " s");
    CHECK(by_caller.load() + by_helper.load() == 200);
    CHECK(by_helper.load() <= 2);
    CHECK(seconds < 1.0);  // a half share would be 2 s
}
