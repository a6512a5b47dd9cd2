#include "device/http/event_hub.h"

namespace px::device {

EventHub::EventHub(size_t capacity) : capacity_(capacity) {}

void EventHub::Publish(const nlohmann::json& event) {
  std::string data = event.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back({next_id_++, std::move(data)});
    if (events_.size() > capacity_) events_.pop_front();
  }
  published_.notify_all();
}

uint64_t EventHub::LastId() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return next_id_ - 1;
}

std::vector<NumberedEvent> EventHub::WaitAfter(uint64_t after_id, std::chrono::milliseconds timeout, bool* missed) {
  std::unique_lock<std::mutex> lock(mutex_);
  published_.wait_for(lock, timeout, [&] { return closed_ || next_id_ - 1 > after_id; });
  *missed = !events_.empty() && events_.front().id > after_id + 1;
  std::vector<NumberedEvent> out;
  if (closed_) return out;
  for (const NumberedEvent& event : events_) {
    if (event.id > after_id) out.push_back(event);
  }
  return out;
}

void EventHub::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  published_.notify_all();
}

bool EventHub::closed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return closed_;
}

}  // namespace px::device
