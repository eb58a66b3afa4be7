// Transparent huge pages for the whole program. lodstream's jobs touch large arrays once each, page by page
// (an imported mesh, its welded copy, a simplifier's quadrics and adjacency, a bake's clusters), and on a
// virtual machine every 4 KiB page fault costs microseconds: on the 2-core VM of BENCHMARKS.md a third of an
// elephant_5m bake. glibc (2.35 and later) backs malloc's large chunks with transparent huge pages when its
// tunable glibc.malloc.hugetlb=1 is set, and tunables are read only when a process starts; so the program
// re-executes itself once with it set (BENCHMARKS.md, "Huge pages": elephant_5m bake 24.7 → 16.7 s, packages
// byte-identical).
#pragma once

namespace lodstream::cli {

// Re-executes /proc/self/exe with `argv` and GLIBC_TUNABLES extended by glibc.malloc.hugetlb=1, unless
// LODSTREAM_HUGE_PAGES=0, GLIBC_TUNABLES already names that tunable (so it happens once), or the program runs
// under valgrind (which would not follow the exec). Returns only when it does not re-execute or the exec
// failed (the program then runs as it is). Cost: one exec, about a millisecond.
void restart_with_huge_pages(char** argv);

}  // namespace lodstream::cli
