// How force_loop (force_loop.h) hands out the end of its parallel region: the force sums and the
// integrator's end of step, by blocks of particles, to whichever thread is free, each block as soon
// as no thread still in its pair loops can read or write it.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <vector>

namespace gravsweep {

/// A thread's flag "my pair and wall loops are done", in its own cache line.
struct alignas(64) LoopsDone {
  std::atomic<int> done{0};
};

/// The end of force_loop's region, handed out by blocks of kFinishBlock particles in index order
/// to whichever thread asks next, instead of an even share per thread after a barrier. Thread t
/// reads and writes only particles from its first row on (each pair is listed under its smaller
/// index), so a block is ready once the threads whose rows begin at or before its last particle
/// are done: a thread that ends its loops early finishes the particles below the next thread's
/// rows while that thread still runs. Which thread finishes a particle changes no bit (the sum's
/// order is fixed, add_thread_sums; the findings merge by min and max).
struct FinishQueue {
  explicit FinishQueue(int threads) : loops(static_cast<std::size_t>(std::max(1, threads))) {}
  std::atomic<std::size_t> next_block{0};
  std::vector<LoopsDone> loops;

  /// Marks thread t's loops done (release: its buffer writes are visible to the acquirer) and
  /// wakes a thread that sleeps on it.
  void mark_done(int t) {
    std::atomic<int>& d = loops[static_cast<std::size_t>(t)].done;
    d.store(1, std::memory_order_release);
    d.notify_all();
  }
  /// Waits until every thread whose rows begin before `end` (first: each thread's first row) is
  /// done; returns whether it had to wait. Spins briefly, then sleeps (futex) as the OpenMP
  /// barrier does under GOMP_SPINCOUNT (scheduler/cli/main.cpp): a waiter that spins for the
  /// whole imbalance slowed the other thread's loops by 5-15 % on a 2-core virtual machine.
  bool wait_ready(const std::size_t* first, int nt, std::size_t end) {
    bool waited = false;
    for (int t = 0; t < nt && first[t] < end; ++t) {
      std::atomic<int>& d = loops[static_cast<std::size_t>(t)].done;
      for (int spin = 0; d.load(std::memory_order_acquire) == 0; ++spin) {
        waited = true;
        if (spin < kSpins)
          spin_pause();
        else
          d.wait(0, std::memory_order_acquire);
      }
    }
    return waited;
  }
  /// Pauses before a waiter sleeps: about the OpenMP barrier's GOMP_SPINCOUNT.
  static constexpr int kSpins = 500;
  static void spin_pause() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
};

}  // namespace gravsweep
