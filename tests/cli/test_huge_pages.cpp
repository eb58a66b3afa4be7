// The program restarts itself once with glibc's huge-page tunable (apps/lodstream/huge_pages.hpp), unless
// told not to: seen in the environment its running image started with.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <iterator>

#include "support/run.hpp"

using namespace lodstream::test;

namespace {

// The environment block a running `lodstream link` started with ('\0'-separated; glibc may split its
// GLIBC_TUNABLES value in place while parsing it).
std::string environment_of_a_running_link() {
  BackgroundProcess link({"link", "--listen", "127.0.0.1:0", "--to", "127.0.0.1:9"});
  EXPECT_NE(link.read_line().find("listening on"), std::string::npos);
  std::ifstream in("/proc/" + std::to_string(link.pid()) + "/environ", std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool has(const std::string& env, const std::string& what) {
  return env.find(what) != std::string::npos;
}

}  // namespace

TEST(HugePages, TheProgramRunsWithGlibcsHugePageTunableUnlessToldNotTo) {
  ::unsetenv("GLIBC_TUNABLES");
  EXPECT_TRUE(has(environment_of_a_running_link(), "GLIBC_TUNABLES=glibc.malloc.hugetlb=1"));
  ::setenv("GLIBC_TUNABLES", "glibc.malloc.arena_max=2", 1);  // other tunables are kept
  const std::string env = environment_of_a_running_link();
  EXPECT_TRUE(has(env, "GLIBC_TUNABLES=glibc.malloc.arena_max=2"));
  EXPECT_TRUE(has(env, "glibc.malloc.hugetlb=1"));
  ::unsetenv("GLIBC_TUNABLES");
  ::setenv("LODSTREAM_HUGE_PAGES", "0", 1);
  EXPECT_FALSE(has(environment_of_a_running_link(), "hugetlb"));
  ::unsetenv("LODSTREAM_HUGE_PAGES");
}
