#include "kodawari/worker_pool.hpp"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "kodawari/parallel.hpp"

namespace kodawari {

namespace {

struct Job {
  const std::function<void(std::size_t, std::size_t)>* body = nullptr;
  std::size_t count = 0, grain = 1, chunks = 0;
  std::atomic<std::size_t> next{0};  // the next chunk to take
  std::atomic<std::size_t> done{0};  // chunks finished
  std::mutex mutex;
  std::condition_variable finished;

  // Takes and runs chunks until none are left. `body` is touched only for a chunk taken
  // below `chunks`, and the caller returns only once all of them are done, so a worker
  // that runs this after the caller returned touches nothing but the Job it shares.
  void work() {
    for (std::size_t c = next.fetch_add(1); c < chunks; c = next.fetch_add(1)) {
      (*body)(c * grain, std::min(count, (c + 1) * grain));
      if (done.fetch_add(1) + 1 == chunks) {
        std::lock_guard<std::mutex> lock(mutex);
        finished.notify_all();
      }
    }
  }
};

class Pool {
 public:
  explicit Pool(unsigned workers) {
    for (unsigned w = 0; w < workers; ++w) std::thread([this] { serve(); }).detach();
    size_ = workers;
  }

  unsigned size() const { return size_; }

  // Offers `job` to up to `wanted` sleeping workers.
  void offer(const std::shared_ptr<Job>& job, unsigned wanted) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = job;
      ++generation_;
      wanted_ = wanted;
    }
    wake_.notify_all();
  }

  void withdraw() {
    std::lock_guard<std::mutex> lock(mutex_);
    job_.reset();
    wanted_ = 0;
  }

  // Held by the one call using the workers; a call that cannot take it runs alone.
  bool try_claim() {
    bool expected = false;
    return busy_.compare_exchange_strong(expected, true);
  }
  void release() { busy_.store(false); }

 private:
  void serve() {
    std::size_t seen = 0;
    for (;;) {
      std::shared_ptr<Job> job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return generation_ != seen && wanted_ > 0 && job_; });
        seen = generation_;
        --wanted_;
        job = job_;
      }
      job->work();
    }
  }

  std::mutex mutex_;
  std::atomic<bool> busy_{false};
  std::condition_variable wake_;
  std::shared_ptr<Job> job_;
  std::size_t generation_ = 0;
  unsigned wanted_ = 0;
  unsigned size_ = 0;
};

Pool& pool() {
  // Never destroyed: its threads sleep until the process ends.
  static Pool* instance = new Pool(std::max(1u, resolve_thread_count(0)) - 1);
  return *instance;
}

}  // namespace

void parallel_chunks(std::size_t count, unsigned threads, std::size_t grain,
                     const std::function<void(std::size_t, std::size_t)>& body) {
  grain = std::max<std::size_t>(1, grain);
  const std::size_t chunks = (count + grain - 1) / grain;
  const unsigned wanted = static_cast<unsigned>(
      std::min<std::size_t>(std::min<std::size_t>(resolve_thread_count(threads), chunks), pool().size() + 1));
  if (wanted <= 1 || !pool().try_claim()) {
    for (std::size_t c = 0; c < chunks; ++c) body(c * grain, std::min(count, (c + 1) * grain));
    return;
  }
  auto job = std::make_shared<Job>();
  job->body = &body;
  job->count = count;
  job->grain = grain;
  job->chunks = chunks;
  pool().offer(job, wanted - 1);
  job->work();
  {
    std::unique_lock<std::mutex> lock(job->mutex);
    job->finished.wait(lock, [&] { return job->done.load() == chunks; });
  }
  pool().withdraw();
  pool().release();
}

}  // namespace kodawari
