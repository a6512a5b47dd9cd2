#include "device/http/rate_limiter.h"

#include <algorithm>

namespace px::device {

RateLimiter::RateLimiter(double per_second) : per_second_(per_second), burst_(2 * per_second) {}

bool RateLimiter::Allow(const std::string& address, Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  // Forget full buckets now and then, so a stream of new addresses cannot grow the map forever.
  if (now - last_sweep_ > std::chrono::seconds(60)) {
    last_sweep_ = now;
    for (auto it = buckets_.begin(); it != buckets_.end();) {
      const double idle_s = std::chrono::duration<double>(now - it->second.refilled).count();
      it = it->second.tokens + idle_s * per_second_ >= burst_ ? buckets_.erase(it) : std::next(it);
    }
  }
  auto [it, fresh] = buckets_.try_emplace(address, Bucket{burst_, now});
  Bucket& bucket = it->second;
  if (!fresh) {
    const double elapsed_s = std::chrono::duration<double>(now - bucket.refilled).count();
    bucket.tokens = std::min(burst_, bucket.tokens + std::max(0.0, elapsed_s) * per_second_);
    bucket.refilled = now;
  }
  if (bucket.tokens < 1) return false;
  bucket.tokens -= 1;
  return true;
}

}  // namespace px::device
