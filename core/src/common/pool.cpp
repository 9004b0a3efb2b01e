// ThreadPool (pool.hpp): threads that spin up to 1 ms for the next job, then sleep on a condition
// variable.
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
/// A sleeping thread looks at what it waits for at least this often.
constexpr std::chrono::milliseconds kSleepLook{50};

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

}  // namespace

template <class T>
T ThreadPool::wait_change(const std::atomic<T>& a, T old) {
  T now = old;
  if (changed(a, old, kPauses, now)) return now;
  const auto until = std::chrono::steady_clock::now() + kSpinTime;
  do {
    if (changed(a, old, kPausesPerRound, now)) return now;
    std::this_thread::yield();
  } while (std::chrono::steady_clock::now() < until);
  // Asleep on a condition variable, the value looked at under its mutex (which every change takes
  // before notifying: wake), so no change is missed. Not std::atomic::wait: MinGW's libstdc++
  // (GCC 12) implements it without futexes.
  std::unique_lock<std::mutex> lock(sleep_mutex_);
  sleepers_.fetch_add(1, std::memory_order_seq_cst);
  std::atomic_thread_fence(std::memory_order_seq_cst);  // pairs with wake's: one of us sees the other
  // Looked at again every kSleepLook even without a notification: a wake-up lost to the platform
  // then costs that long, never a hang.
  while (!sleep_.wait_for(lock, kSleepLook, [&] { return (now = a.load(std::memory_order_acquire)) != old; })) {
  }
  sleepers_.fetch_sub(1, std::memory_order_relaxed);
  return now;
}

void ThreadPool::wake() {
  // Either this sees the sleeper counted, or the sleeper (counted, then fenced) sees the change and
  // does not sleep. The mutex only when someone sleeps: a busy pool's hand-overs never take it.
  std::atomic_thread_fence(std::memory_order_seq_cst);
  if (sleepers_.load(std::memory_order_relaxed) == 0) return;
  { const std::lock_guard<std::mutex> lock(sleep_mutex_); }
  sleep_.notify_all();
}

void ThreadPool::idle(int round) {
  relax();
  if (round % kPausesPerRound == 0) std::this_thread::yield();
}

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  errors_.resize(static_cast<size_t>(threads));
  taken_ = std::make_unique<Taken[]>(static_cast<size_t>(threads));
  lines_ = std::make_unique<Line[]>(static_cast<size_t>(threads));
  workers_.reserve(static_cast<size_t>(threads - 1));
  for (int i = 0; i + 1 < threads; ++i) workers_.emplace_back([this, i] { work(i); });
}

ThreadPool::~ThreadPool() {
  publish(0);
  for (std::thread& t : workers_) t.join();
}

uint64_t ThreadPool::publish(int parts) {
  const uint64_t number = (job_.load(std::memory_order_relaxed) >> 16) + 1;
  job_.store(number << 16 | static_cast<uint64_t>(parts), std::memory_order_release);
  wake();
  return number;
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
  const uint64_t job = publish(parts);
  run_part(0);
  // The parts no worker has started yet, here (a worker the system has not run holds up nothing).
  for (int part = 1; part < parts && pending_.load(std::memory_order_acquire) != 0; ++part)
    if (take(part, job)) {
      run_part(part);
      pending_.fetch_sub(1, std::memory_order_acq_rel);
    }
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
    if (index + 1 < parts && take(index + 1, seen >> 16)) {
      run_part(index + 1);
      if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) wake();
    }
  }
}

}  // namespace embra
