// Helpers for tests that run the built `lodstream` program and read its output, and find fetched test data.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lodstream::test {

struct RunResult {
  int status = -1;              // exit status, or 128 + signal number when it was killed by a signal
  std::string out;              // standard output
  std::string err;              // standard error
  nlohmann::json json() const;  // standard output parsed as JSON (fails the test when it is not)
};

// Runs build/bin/lodstream with `args` (no shell), waits, returns its exit status and output.
RunResult run_lodstream(const std::vector<std::string>& args);

// A `lodstream` process left running (a server, a link): its standard output is read line by line; standard
// error goes to the test's. stop() (or the destructor) sends SIGTERM and returns the exit status.
class BackgroundProcess {
 public:
  explicit BackgroundProcess(const std::vector<std::string>& args);
  ~BackgroundProcess();
  BackgroundProcess(const BackgroundProcess&) = delete;
  BackgroundProcess& operator=(const BackgroundProcess&) = delete;
  // The next line of standard output without its newline; empty after `timeout_s` or at end of output.
  std::string read_line(double timeout_s = 10.0);
  int stop();
  int pid() const { return pid_; }

 private:
  int pid_ = -1;
  int out_ = -1;
  std::string pending_;
};

// Path of a file fetched by scripts/fetch-data into data/; fails the calling test (ADD_FAILURE) with the
// command to run when the file is missing. `make test` fetches everything before the tests run.
std::filesystem::path data_file(const std::string& name);

// A fresh, empty temporary directory, removed at process exit.
std::filesystem::path temp_dir();

}  // namespace lodstream::test
