// Timing a job that the benchmarks repeat: the process's or the thread's CPU seconds beside wall time, and
// the median of the repetitions.
#pragma once

#include <time.h>

#include <algorithm>
#include <vector>

namespace lodstream::cli {

// CPU seconds of the whole process, all threads together (CLOCK_PROCESS_CPUTIME_ID). Beside wall time it
// shows how many cores a job kept busy, and it is steadier than wall time on a loaded machine.
inline double process_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

// CPU seconds of the calling thread alone (CLOCK_THREAD_CPUTIME_ID): a one-core job's time, whatever else the
// process runs. A system call on some VMs (about a microsecond): read it per job, not per small item.
inline double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

// The median of `values` (the mean of the middle two for an even count); requires values non-empty.
inline double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace lodstream::cli
