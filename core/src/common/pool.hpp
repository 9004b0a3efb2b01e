// The solver's threads: a fixed pool that splits one range of independent items (the constraints of
// one colour, the chains of one colour, the particles of a pass) into one contiguous part per
// thread, runs the parts at once and returns when all are done; or runs one line of steps per
// thread whose steps wait only for the steps of other lines they need (run_lines: the colours of a
// panel mesh's islands, each waiting for the borders of the colour before).
//
// What a part computes never depends on how the range was split: every item reads and writes only
// its own particles (a colour's constraints share no movable particle), and the kernels give the
// same bits for an item whether it is computed in a block of lanes or alone (lanes.hpp). So the
// result is the same at any thread count, bit for bit.
//
// The caller's thread runs part 0; a waiting thread spins for up to 1 ms (yielding its core between
// rounds of pauses), then sleeps on a condition variable (looking again every 50 ms), so a busy
// pool hands work over in microseconds and an idle one costs next to nothing after that millisecond. Whoever starts a
// part first takes it: a worker its own, the caller, once its part 0 is done, any a worker has not started. So a worker
// the system has not let run (a host's other threads, a browser drawing on the other core) delays nothing: the caller
// does its part instead of waiting for its turn. One pool serves one world, one call at a time (the C ABI's
// one-call-at-a-time rule).
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace embra {

class ThreadPool {
 public:
  /// A pool of `threads` threads in all, the caller's included (1: no workers; every range runs on
  /// the caller). 0 takes std::thread::hardware_concurrency().
  explicit ThreadPool(int threads = 1);  // at most 65535
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  /// Threads in all, the caller's included.
  int size() const { return static_cast<int>(workers_.size()) + 1; }

  /// Calls fn(part_begin, part_end, part) over [begin, end) cut into at most size() contiguous parts,
  /// each (but the last) a multiple of `align` items long and at least `grain` items; fewer parts
  /// when the range is short (a range under 2 * grain runs on the caller alone). `part` is in
  /// [0, size()): the index of per-thread scratch. Returns when every part is done; an exception a
  /// part threw (on whichever thread) is thrown here then, the first part's first.
  template <class F>
  void run(size_t begin, size_t end, size_t align, size_t grain, F&& fn) {
    const size_t n = end > begin ? end - begin : 0;
    size_t parts = workers_.empty() || grain == 0 ? 1 : std::min<size_t>(static_cast<size_t>(size()), n / grain);
    if (parts <= 1) {
      if (n > 0) fn(begin, end, 0);
      return;
    }
    // Equal parts, rounded up to `align`; the last takes what is left.
    size_t step = (n + parts - 1) / parts;
    step = (step + align - 1) / align * align;
    parts = (n + step - 1) / step;
    Job<F> job{&fn, begin, end, step};
    dispatch(&Job<F>::call, &job, static_cast<int>(parts));
  }

  /// Calls fn(part) for part in [0, parts) (at most size()), each on its own thread, the caller's
  /// part 0; returns when all are done, throwing what a part threw as run() does. For parts the
  /// caller cuts itself.
  template <class F>
  void run_parts(int parts, F&& fn) {
    parts = std::clamp(parts, 1, size());
    if (parts == 1) return fn(0);
    using Fn = std::remove_reference_t<F>;
    Parts<Fn> job{&fn};
    dispatch(&Parts<Fn>::call, &job, parts);
  }

  /// Runs `lines` sequences of `steps` steps each (lines at most size()): step k of line s once step
  /// k - 1 of line s has ended and ready(s, k, done) holds, where done(q) is the number of line q's
  /// steps ended so far (read with acquire: what they wrote is visible to the caller of done). Part s
  /// runs line s's steps in turn, and while its own line cannot go on it takes the next step of
  /// another line whose part has not started yet (a worker the system has not run), or of any line
  /// once it has waited kStealRounds rounds; so whichever threads run, the lines end. step(s, k) runs
  /// each step once, on whichever thread took it; it may throw, as run()'s parts may.
  ///
  /// `ready` must hold for the line with the fewest steps ended (while any is left), whatever the
  /// others have done: else no step could run. Steps of different lines that `ready` lets overlap
  /// must share no data; that is the caller's to ensure.
  template <class Ready, class Step>
  void run_lines(int lines, int steps, Ready&& ready, Step&& step) {
    lines = std::clamp(lines, 1, size());
    if (lines == 1) {
      for (int k = 0; k < steps; ++k) step(0, k);
      return;
    }
    for (int s = 0; s < lines; ++s) {
      Line& l = lines_[static_cast<size_t>(s)];
      l.claimed.store(0, std::memory_order_relaxed);
      l.done.store(0, std::memory_order_relaxed);
      l.started.store(false, std::memory_order_relaxed);
    }
    stopped_.store(false, std::memory_order_relaxed);  // the job's publication releases these
    const auto done = [this](int q) { return lines_[static_cast<size_t>(q)].done.load(std::memory_order_acquire); };
    const auto part = [&](int me) {
      lines_[static_cast<size_t>(me)].started.store(true, std::memory_order_relaxed);
      for (int waited = 0;;) {
        bool left = false, ran = false;
        for (int k = 0; k < lines && !ran; ++k) {
          const int s = (me + k) % lines;  // its own line first
          Line& l = lines_[static_cast<size_t>(s)];
          int next = l.claimed.load(std::memory_order_acquire);
          if (next >= steps) continue;
          left = true;
          if (k > 0 && waited < kStealRounds && l.started.load(std::memory_order_relaxed)) continue;
          if (l.done.load(std::memory_order_acquire) != next || !ready(s, next, done)) continue;
          if (!l.claimed.compare_exchange_strong(next, next + 1, std::memory_order_acq_rel)) continue;
          try {
            step(s, next);
          } catch (...) {
            stopped_.store(true, std::memory_order_relaxed);  // the other parts stop waiting for it
            throw;
          }
          l.done.store(next + 1, std::memory_order_release);
          ran = true;
        }
        if (!left || stopped_.load(std::memory_order_relaxed)) return;
        waited = ran ? 0 : waited + 1;
        if (!ran) idle(waited);
      }
    };
    run_parts(lines, part);
  }

  /// run() over [begin, end) where each part appends what it finds to its own list
  /// (find(part_begin, part_end, list)), the lists then appended to `out` part after part: `out`
  /// gains the items in range order, as if found on one thread, at any thread count. `parts` is the
  /// caller's scratch, kept from call to call so that its lists keep their storage.
  template <class T, class F>
  void collect(size_t begin, size_t end, size_t grain, std::vector<std::vector<T>>& parts, std::vector<T>& out,
               F&& find) {
    parts.resize(static_cast<size_t>(size()));
    for (std::vector<T>& part : parts) part.clear();
    run(begin, end, 1, grain, [&](size_t b, size_t e, int part) { find(b, e, parts[static_cast<size_t>(part)]); });
    for (const std::vector<T>& part : parts) out.insert(out.end(), part.begin(), part.end());
  }

 private:
  /// run_lines: rounds a part waits on its own line before it takes steps of lines whose parts run
  /// (about 10 us: a step of the islands is a few to twenty).
  static constexpr int kStealRounds = 256;
  /// A waiting round of run_lines (`round` of them so far): a pause, and the core given up now and then.
  static void idle(int round);
  struct alignas(64) Line {  // run_lines: one line's steps taken and ended, and whether its part started
    std::atomic<int> claimed{0}, done{0};
    std::atomic<bool> started{false};
  };
  std::unique_ptr<Line[]> lines_;
  std::atomic<bool> stopped_{false};  // a step of run_lines threw

  template <class F>
  struct Job {
    F* fn;
    size_t begin, end, step;
    static void call(void* self, int part) {
      const Job& j = *static_cast<Job*>(self);
      const size_t b = j.begin + static_cast<size_t>(part) * j.step;
      const size_t e = std::min(j.end, b + j.step);
      if (b < e) (*j.fn)(b, e, part);
    }
  };

  template <class F>
  struct Parts {
    F* fn;
    static void call(void* self, int part) { (*static_cast<Parts*>(self)->fn)(part); }
  };

  /// Runs part `part` of the current job, keeping what it throws for dispatch to throw.
  void run_part(int part) noexcept;

  /// Runs call(context, p) for p in [0, parts): parts 1 .. parts - 1 on workers, 0 here.
  void dispatch(void (*call)(void*, int), void* context, int parts);
  uint64_t publish(int parts);  // a new job with `parts` parts (0: stop); returns its number
  void work(int index);
  /// Waits until `a` holds a value other than `old` (spinning, then asleep); returns it.
  template <class T>
  T wait_change(const std::atomic<T>& a, T old);
  void wake();  // after a change a sleeper may wait for: wakes every sleeper

  std::vector<std::thread> workers_;
  // The current job. call_ and context_ are written before job_ publishes them and read only by the
  // workers that have a part, which the caller waits for before it writes them again.
  void (*call_)(void*, int) = nullptr;
  void* context_ = nullptr;
  // (job number << 16) | parts: one word, so that a worker sees a job's number and part count
  // together. 0 parts: stop.
  std::atomic<uint64_t> job_{0};
  std::atomic<int> pending_{0};  // worker parts of the current job not yet done
  // Per part: the number of the last job whose part someone took (take()); a line each.
  struct alignas(64) Taken {
    std::atomic<uint64_t> job{0};
  };
  std::unique_ptr<Taken[]> taken_;
  /// True for whoever takes part `part` of job `job` first (its runner), false for the others, and
  /// for a worker that sees a job only after the caller has moved on to a later one.
  bool take(int part, uint64_t job) {
    std::atomic<uint64_t>& taken = taken_[static_cast<size_t>(part)].job;
    for (uint64_t last = taken.load(std::memory_order_acquire); last < job;)
      if (taken.compare_exchange_weak(last, job, std::memory_order_acq_rel, std::memory_order_acquire)) return true;
    return false;
  }
  std::vector<std::exception_ptr> errors_;  // per part: what it threw (a worker must never unwind)
  std::mutex sleep_mutex_;                  // wait_change's sleep: job_ and pending_ looked at under it
  std::condition_variable sleep_;
  std::atomic<int> sleepers_{0};  // threads asleep in wait_change (or about to be)
};

}  // namespace embra
