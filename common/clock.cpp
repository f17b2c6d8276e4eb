#include "common/clock.hpp"

#include <chrono>

namespace sg {

int64_t now_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

}  // namespace sg
