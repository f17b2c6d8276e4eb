// GCC 12's -fsanitize=vptr reports LCM 1.3.1's own C++ dispatch with no project code involved:
// "lcm-cpp-impl.hpp:108: member access within address ... which does not point to an object of
// type 'LCMMHUntypedSubscription' ... object has invalid vptr", on a subscription LCM itself
// allocated. clang's vptr check and AddressSanitizer find nothing in the same program, and it
// prints n=1. So the GCC sanitized build leaves the vptr check out (CMakeLists.txt):
//
//   g++ -std=c++20 -O0 -fsanitize=undefined -fno-sanitize-recover=all lcm_vptr_repro.cpp -llcm
//   ./a.out                                           # GCC 12.2: the report, then abort
//   clang++ -std=c++20 -O1 -fsanitize=address,undefined lcm_vptr_repro.cpp -llcm && ./a.out
//                                                     # n=1, no report
#include <cstdio>
#include <lcm/lcm-cpp.hpp>

struct Handler {
  int n = 0;
  void on(const lcm::ReceiveBuffer*, const std::string&) { ++n; }
};

int main() {
  lcm::LCM lcm("memq://");
  Handler h;
  lcm.subscribe("X", &Handler::on, &h);
  const char bytes[4] = {1, 2, 3, 4};
  lcm.publish("X", bytes, 4);
  lcm.handleTimeout(100);
  std::printf("n=%d\n", h.n);
  return h.n == 1 ? 0 : 1;
}
