// WorkTeam: the threads the core's parallel stages run on, made so that a thread the operating system
// deschedules (another program holds its core) costs its share of the work, not a scheduler slice.
//
// A job is `count` indexed pieces of work. The calling thread publishes it and works on it too. Each worker
// has a home range of the indices (worker w of T: [w count / T, (w + 1) count / T)) and claims its next
// unclaimed index there, one at a time (a compare-and-swap on the range's counter, which also names the job);
// when its range is used up it takes indices from the others' ranges the same way. The job is done when every
// index has run, not when every thread has arrived: a helper that has not woken up yet simply finds its range
// taken, and the caller does its share. So a team is never slower than its caller alone by more than the one
// piece a preempted helper holds. The home ranges keep each piece on the same core from job to job (the
// same band of rows every substep), so its data stays in that core's cache: with one counter for the whole
// job the two workers took the bands in turns, a band's rows moved between the cores' caches every substep,
// and two threads ran a 128 x 128 Verlet substep in 0.87 of one thread's time on a 2-vCPU Intel Xeon. OpenMP's barriers, by contrast, wait for
// every thread of the team, and a descheduled one arrives a whole slice late, at every barrier (measured in
// docs/PERFORMANCE.md, "Threads under load": up to 53x slower than one thread).
//
// Waiting spins briefly (the next job of a substep comes within microseconds) and then blocks in the kernel
// (a futex), so an idle or waiting thread gives its core to whoever needs it.
//
// Which index runs on which thread varies from run to run; every user makes each index's result independent
// of that (its own output rows, its own partial sums, scratch per worker), so results are bit-identical for
// any team size. One team serves the whole process; a job started while another runs (two simulations
// stepped from two threads) runs on its caller alone, with the same result.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

namespace clothsim {

class WorkTeam {
public:
    // The most threads a job may ask for (the caller and its helpers).
    static constexpr int kMaxThreads = 64;

    static WorkTeam& shared();

    // Calls work(index, worker) for every index in [0, count) on at most `threads` threads (the caller is
    // worker 0, helpers 1 .. threads - 1) and returns when all have run. With threads <= 1, count <= 1, or the
    // team busy with another caller's job, the caller runs them all, in order, as worker 0.
    template <class Work>
    void run(int threads, int count, Work&& work) {
        using W = std::remove_reference_t<Work>;
        run_job(threads, count, &work, [](void* w, int index, int worker) { (*static_cast<W*>(w))(index, worker); });
    }

    // Calls work(first, last) for the pieces [first, last) of `piece` items each that cover [0, items), through
    // run(): the same pieces, each its own work, on any number of threads.
    template <class Work>
    void run_pieces(int threads, std::size_t items, std::size_t piece, Work&& work) {
        run(threads, pieces(items, piece), [&](int index, int) {
            const std::size_t first = static_cast<std::size_t>(index) * piece;
            work(first, first + piece < items ? first + piece : items);
        });
    }
    // How many pieces of `piece` items cover `items`.
    static int pieces(std::size_t items, std::size_t piece) { return static_cast<int>((items + piece - 1) / piece); }

    // The hardware threads of this machine, read once.
    static int cores();

    WorkTeam(const WorkTeam&) = delete;
    WorkTeam& operator=(const WorkTeam&) = delete;

private:
    using Call = void (*)(void*, int, int);
    WorkTeam() = default;
    void run_job(int threads, int count, void* work, Call call);
    void start_helpers(int helpers);
    void helper_loop(int worker, std::uint32_t seen);
    // Claims and runs indices of job `job` until none is left (or the job is no longer the current one).
    void work_on(std::uint32_t job, int worker);

    std::atomic<bool> busy_{false};              // a job is under way
    std::atomic<std::uint32_t> job_{0};          // the current job's number; helpers sleep on it (a futex word)
    // Worker w's home range of the current job: its counter (job number << 32 | next unclaimed index), on a
    // cache line of its own, and its end in ends_[j % 2][w] for job j: a helper that finished the last index
    // of job j may read the end while the caller is publishing job j + 1, and must still see that job j has
    // no index left there.
    struct alignas(64) Range {
        std::atomic<std::uint64_t> claim{0};
    };
    Range ranges_[kMaxThreads];
    std::atomic<int> ends_[2][kMaxThreads] = {};
    std::atomic<int> ranges_used_[2] = {0, 0};  // the current job's thread count, for job j in [j % 2]
    std::atomic<int> total_[2] = {0, 0};        // ... and its index count
    std::atomic<int> helpers_wanted_{0};         // helpers that may join the current job (threads - 1)
    std::atomic<int> done_{0};                   // indices of the current job that have run; the caller sleeps on it
    void* work_ = nullptr;                       // the current job (read after a successful claim)
    Call call_ = nullptr;
    std::atomic<int> sleepers_{0};               // helpers blocked in the kernel on job_
    std::atomic<bool> caller_asleep_{false};     // the caller is blocked in the kernel on done_
    std::vector<std::thread> helpers_;
};

}  // namespace clothsim
