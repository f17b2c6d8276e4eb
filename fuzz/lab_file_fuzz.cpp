// Drives the lab file reader (lab/lab_file.hpp) as `sg-lab` does: the input is the text of a lab
// file. Asserts, beyond not crashing: the only error is sg::lab::LabError, and it names the file;
// a file that reads has processes only on its hosts, unique names, and something to run.

#include <cstdint>
#include <set>
#include <string>

#include "fuzz/fuzz_support.hpp"
#include "lab/lab_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const sg::lab::LabFile lab = sg::lab::parse_lab_file(text, "lab.yaml");
    std::set<std::string> hosts, names;
    for (const auto& h : lab.hosts) hosts.insert(h.name);
    for (const auto& p : lab.processes) {
      SG_FUZZ_CHECK(hosts.count(p.host) == 1, "process '%s' on unknown host", p.name.c_str());
      SG_FUZZ_CHECK(names.insert(p.name).second, "process '%s' twice", p.name.c_str());
      SG_FUZZ_CHECK(!p.run.empty() && !p.run[0].empty(), "process '%s' runs nothing",
                    p.name.c_str());
    }
  } catch (const sg::lab::LabError& e) {
    SG_FUZZ_CHECK(std::string(e.what()).starts_with("lab.yaml"), "error without the file: %s",
                  e.what());
  } catch (const std::exception& e) {
    SG_FUZZ_CHECK(false, "not a LabError: %s", e.what());
  }
  return 0;
}
