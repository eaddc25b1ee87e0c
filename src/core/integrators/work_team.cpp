#include "integrators/work_team.hpp"

#include <algorithm>
#include <climits>

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define CLOTHSIM_PAUSE() _mm_pause()
#else
#define CLOTHSIM_PAUSE() ((void)0)
#endif

namespace clothsim {

namespace {

// Spins before blocking: about 20-50 microseconds of pause instructions, longer than the gap between the
// jobs of one substep (so a running team never sleeps inside a substep) and short against a scheduler slice
// (so a thread whose partner was descheduled soon hands its core over).
constexpr int kSpins = 4000;

// Blocking through the futex system call directly: sleeps while *word == expected (returns at once when it
// differs), and wakes the sleepers on word.
template <class T>
void futex_wait(std::atomic<T>& word, T expected) {
    static_assert(sizeof(T) == 4 && std::atomic<T>::is_always_lock_free, "a futex is a 32-bit word");
    syscall(SYS_futex, reinterpret_cast<T*>(&word), FUTEX_WAIT_PRIVATE, expected, nullptr, nullptr, 0);
}
template <class T>
void futex_wake_all(std::atomic<T>& word) {
    syscall(SYS_futex, reinterpret_cast<T*>(&word), FUTEX_WAKE_PRIVATE, INT_MAX, nullptr, nullptr, 0);
}

}  // namespace

WorkTeam& WorkTeam::shared() {
    // Made once and never destroyed, as an OpenMP runtime's pool: the helpers sleep in the kernel when the
    // process exits and end with it, so no exit path waits on them (a join at exit hung when a helper had not
    // started yet, and threads ending while LeakSanitizer stopped the process to scan it crashed its tracer).
    static WorkTeam* const team = new WorkTeam;
    return *team;
}

int WorkTeam::cores() {
    // Read once: glibc answers hardware_concurrency() by reading /sys/devices/system/cpu/online.
    static const int n = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    return n;
}


void WorkTeam::start_helpers(int helpers) {
    while (static_cast<int>(helpers_.size()) < helpers) {
        const int worker = static_cast<int>(helpers_.size()) + 1;
        // The job number as it is before the job about to be published: a helper that starts late still
        // sees that job (or a later one) as new.
        const std::uint32_t seen = job_.load();
        helpers_.emplace_back([this, worker, seen] { helper_loop(worker, seen); });
    }
}

void WorkTeam::run_job(int threads, int count, void* work, Call call) {
    threads = std::min({threads, count, kMaxThreads});
    bool expected = false;
    if (threads <= 1 || !busy_.compare_exchange_strong(expected, true, std::memory_order_acquire)) {
        for (int i = 0; i < count; ++i) call(work, i, 0);
        return;
    }
    start_helpers(threads - 1);
    work_ = work;
    call_ = call;
    const std::uint32_t job = job_.load(std::memory_order_relaxed) + 1;
    for (int w = 0; w < threads; ++w) {
        const long long begin = static_cast<long long>(w) * count / threads;
        ends_[job % 2][w].store(static_cast<int>(static_cast<long long>(w + 1) * count / threads), std::memory_order_relaxed);
        ranges_[w].claim.store(static_cast<std::uint64_t>(job) << 32 | static_cast<std::uint64_t>(begin),
                               std::memory_order_release);
    }
    ranges_used_[job % 2].store(threads, std::memory_order_relaxed);
    total_[job % 2].store(count, std::memory_order_relaxed);
    helpers_wanted_.store(threads - 1, std::memory_order_relaxed);
    done_.store(0, std::memory_order_relaxed);
    job_.store(job);  // sequentially consistent with the sleepers' count (helper_loop); publishes the ranges
    if (sleepers_.load() > 0) futex_wake_all(job_);
    work_on(job, 0);
    for (int spin = 0;; ++spin) {
        const int done = done_.load(std::memory_order_acquire);
        if (done == count) break;
        if (spin < kSpins) {
            CLOTHSIM_PAUSE();
        } else {
            // A helper holds the last pieces: sleep until done_ changes (the helper that finishes the job
            // wakes this thread when it sees it asleep).
            caller_asleep_.store(true);
            if (done_.load() != count) futex_wait(done_, done);
            caller_asleep_.store(false);
        }
    }
    busy_.store(false, std::memory_order_release);
}

void WorkTeam::work_on(std::uint32_t job, int worker) {
    // Its own range first, then the others' in turn.
    const int ranges = ranges_used_[job % 2].load(std::memory_order_relaxed);
    for (int k = 0; k < ranges; ++k) {
        Range& range = ranges_[(worker + k) % ranges];
        const int end = ends_[job % 2][(worker + k) % ranges].load(std::memory_order_relaxed);
        for (;;) {
            std::uint64_t claim = range.claim.load(std::memory_order_acquire);
            if (static_cast<std::uint32_t>(claim >> 32) != job) return;  // the job has moved on
            const int index = static_cast<int>(static_cast<std::uint32_t>(claim));
            if (index >= end) break;  // this range is taken: the next
            if (!range.claim.compare_exchange_weak(claim, claim + 1, std::memory_order_acq_rel, std::memory_order_acquire)) {
                continue;
            }
            // Holding an index of `job`, which cannot finish before it has run: work_, call_ and the ends are
            // its own.
            call_(work_, index, worker);
            const int count = total_[job % 2].load(std::memory_order_relaxed);
            if (done_.fetch_add(1) + 1 == count && caller_asleep_.load()) futex_wake_all(done_);
        }
    }
}

void WorkTeam::helper_loop(int worker, std::uint32_t seen) {
    for (;;) {
        std::uint32_t job = seen;
        for (int spin = 0; (job = job_.load(std::memory_order_acquire)) == seen; ++spin) {
            if (spin < kSpins) {
                CLOTHSIM_PAUSE();
            } else {
                // Counted before the futex reads job_ again: a caller that publishes after the count sees it and
                // wakes this thread; one that published before it changed job_, and the futex returns at once.
                sleepers_.fetch_add(1);
                futex_wait(job_, seen);
                sleepers_.fetch_sub(1);
            }
        }
        seen = job;
        if (worker <= helpers_wanted_.load(std::memory_order_relaxed)) work_on(job, worker);
    }
}

}  // namespace clothsim
