// The daemon's events (Daemon::SetEventListener) kept for the web app's live view: the last few
// hundred, each numbered, so a stream (server-sent events) that reconnects with Last-Event-ID
// continues where it left off, and one that fell too far behind is told to reload. Thread-safe;
// Publish never blocks on a reader.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace px::device {

struct NumberedEvent {
  uint64_t id = 0;
  std::string data;  // the event as one line of JSON
};

class EventHub {
 public:
  explicit EventHub(size_t capacity = 512);

  void Publish(const nlohmann::json& event);
  uint64_t LastId() const;

  // The events after `after_id`, waiting up to `timeout` for the first. `*missed` is set when
  // some were already dropped (the reader should reload its state). Empty after a timeout or Close.
  std::vector<NumberedEvent> WaitAfter(uint64_t after_id, std::chrono::milliseconds timeout, bool* missed);

  // Wakes every waiter for good (the server is stopping).
  void Close();
  bool closed() const;

 private:
  size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable published_;
  std::deque<NumberedEvent> events_;
  uint64_t next_id_ = 1;
  bool closed_ = false;
};

}  // namespace px::device
