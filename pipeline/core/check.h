// PX_CHECK(cond) << "context": aborts with file and line when one of our own invariants breaks.
// Never use it to validate input; input errors return Status.
#pragma once

#include <sstream>

namespace px::internal {

class CheckFailure {
 public:
  CheckFailure(const char* file, int line, const char* condition);
  [[noreturn]] ~CheckFailure();
  template <typename T>
  CheckFailure& operator<<(const T& value) {
    stream_ << value;
    return *this;
  }

 private:
  std::ostringstream stream_;
};

// Lets `PX_CHECK(x) << ...` be a single statement that evaluates the stream only on failure.
struct Voidify {
  void operator&(const CheckFailure&) {}
};

}  // namespace px::internal

#define PX_CHECK(condition) \
  (condition) ? (void)0 : ::px::internal::Voidify() & ::px::internal::CheckFailure(__FILE__, __LINE__, #condition)
