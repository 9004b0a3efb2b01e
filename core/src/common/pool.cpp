// ThreadPool (pool.hpp): threads that spin up to 1 ms for the next job, then sleep on an atomic.
#include "common/pool.hpp"

#include <chrono>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace embra {

namespace {

/// Waits this long before sleeping: the colours of one pass follow each other within microseconds,
/// and the serial parts between passes (a substep's contact lists, sorts and merges) take up to a
/// few hundred microseconds, where a sleeping worker takes tens of microseconds to wake (a futex
/// call each way). A pool left idle waits this long once, then sleeps.
constexpr std::chrono::microseconds kSpinTime{1000};
/// Looks at the atomic between pauses only, this many times (tens of microseconds: a colour's
/// hand-over), then in rounds of kPausesPerRound with a yield after each, so that on a machine with
/// fewer cores than threads a waiting thread gives its core to one with work.
constexpr int kPauses = 4096;
constexpr int kPausesPerRound = 64;

inline void relax() {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#else
  std::this_thread::yield();
#endif
}

/// Looks at `a` up to `looks` times, pausing between them; true (the value in `now`) once it differs
/// from `old`.
template <class T>
bool changed(const std::atomic<T>& a, T old, int looks, T& now) {
  for (int i = 0; i < looks; ++i) {
    now = a.load(std::memory_order_acquire);
    if (now != old) return true;
    relax();
  }
  return false;
}

/// Waits until `a` holds a value other than `old`; returns it.
template <class T>
T wait_change(const std::atomic<T>& a, T old) {
  T now = old;
  if (changed(a, old, kPauses, now)) return now;
  const auto until = std::chrono::steady_clock::now() + kSpinTime;
  do {
    if (changed(a, old, kPausesPerRound, now)) return now;
    std::this_thread::yield();
  } while (std::chrono::steady_clock::now() < until);
  for (;;) {
    a.wait(old, std::memory_order_acquire);
    now = a.load(std::memory_order_acquire);
    if (now != old) return now;
  }
}

}  // namespace

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  errors_.resize(static_cast<size_t>(threads));
  workers_.reserve(static_cast<size_t>(threads - 1));
  for (int i = 0; i + 1 < threads; ++i) workers_.emplace_back([this, i] { work(i); });
}

ThreadPool::~ThreadPool() {
  publish(0);
  for (std::thread& t : workers_) t.join();
}

void ThreadPool::publish(int parts) {
  const uint64_t number = (job_.load(std::memory_order_relaxed) >> 16) + 1;
  job_.store(number << 16 | static_cast<uint64_t>(parts), std::memory_order_release);
  job_.notify_all();
}

void ThreadPool::run_part(int part) noexcept {
  try {
    call_(context_, part);
  } catch (...) {
    errors_[static_cast<size_t>(part)] = std::current_exception();
  }
}

void ThreadPool::dispatch(void (*call)(void*, int), void* context, int parts) {
  call_ = call;
  context_ = context;
  for (std::exception_ptr& e : errors_) e = nullptr;
  pending_.store(parts - 1, std::memory_order_relaxed);
  publish(parts);
  run_part(0);
  for (int left = pending_.load(std::memory_order_acquire); left != 0;) left = wait_change(pending_, left);
  for (const std::exception_ptr& e : errors_)
    if (e) std::rethrow_exception(e);
}

void ThreadPool::work(int index) {
  uint64_t seen = 0;
  for (;;) {
    seen = wait_change(job_, seen);
    const int parts = static_cast<int>(seen & 0xffff);
    if (parts == 0) return;
    if (index + 1 < parts) {
      run_part(index + 1);
      if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) pending_.notify_one();
    }
  }
}

}  // namespace embra
