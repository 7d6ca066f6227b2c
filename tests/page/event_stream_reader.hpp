// The page server's /api/events read on a thread of its own, as a page reads it: each piece of the
// stream is handed to `more` under the reader's lock, and reading goes on while `more` returns true
// and the server keeps the stream open. The page tests' readers (the text of the events, the
// scope's sample batches) are this with what each keeps of the pieces; they read what they keep
// through locked(), as the thread writes it.
#pragma once

#include <httplib.h>

#include <cstddef>
#include <functional>
#include <mutex>
#include <string_view>
#include <thread>
#include <utility>

namespace cia402::page::testing {

class event_stream_reader {
 public:
  event_stream_reader(int port, std::function<bool(std::string_view piece)> more) : more_(std::move(more)) {
    thread_ = std::thread([this, port] {
      httplib::Client c("127.0.0.1", port);
      c.set_read_timeout(5, 0);
      c.Get("/api/events", [this](const char* data, std::size_t n) {
        std::lock_guard lock(mutex_);
        return more_(std::string_view(data, n));
      });
    });
  }
  ~event_stream_reader() { join(); }
  event_stream_reader(const event_stream_reader&) = delete;
  event_stream_reader& operator=(const event_stream_reader&) = delete;

  // Waits until the stream has ended (`more` said enough, the server closed it, or the read timed out).
  void join() {
    if (thread_.joinable()) thread_.join();
  }
  // `f()` under the lock the thread holds while it hands a piece to `more`.
  template <typename F>
  auto locked(F f) {
    std::lock_guard lock(mutex_);
    return f();
  }

 private:
  std::function<bool(std::string_view)> more_;
  std::mutex mutex_;
  std::thread thread_;
};

}  // namespace cia402::page::testing
