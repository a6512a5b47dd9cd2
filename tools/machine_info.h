// What a benchmark figure was measured on: CPU, cores, memory, commit, peak RSS.
#pragma once

#include <string>

namespace px::cli {

struct MachineInfo {
  std::string cpu_model;  // from /proc/cpuinfo
  int cores = 0;          // online CPUs
  double memory_gib = 0;  // physical memory
  std::string commit;     // git commit the binary was configured from ("unknown" outside git)
};

MachineInfo ReadMachineInfo();
// Peak resident set size of this process so far, in MiB (getrusage).
double PeakRssMiB();

}  // namespace px::cli
