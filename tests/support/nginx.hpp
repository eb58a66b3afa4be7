// A real nginx for tests of serving (DESIGN.md: pull works against any static HTTP server). Header-only (the
// including test links Boost).
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <boost/asio.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "support/run.hpp"

namespace lodstream::test {

// A real nginx on loopback serving `root`: configuration in a temporary prefix, no daemon, a free port.
class Nginx {
 public:
  explicit Nginx(const std::filesystem::path& root) {
    namespace asio = boost::asio;
    {
      asio::io_context io;
      asio::ip::tcp::acceptor probe(io, {asio::ip::make_address("127.0.0.1"), 0});
      port_ = probe.local_endpoint().port();
    }
    const auto prefix = test::temp_dir();
    std::filesystem::create_directories(prefix / "logs");
    const auto conf = prefix / "nginx.conf";
    std::ofstream(conf) << "daemon off;\nmaster_process off;\nworker_processes 1;\npid "
                        << (prefix / "nginx.pid").string() << ";\nerror_log "
                        << (prefix / "logs/error.log").string()
                        << ";\nevents { worker_connections 64; }\nhttp {\n  access_log off;\n"
                        << "  client_body_temp_path " << prefix.string() << "/body;\n"
                        << "  proxy_temp_path " << prefix.string() << "/proxy;\n"
                        << "  fastcgi_temp_path " << prefix.string() << "/fastcgi;\n"
                        << "  uwsgi_temp_path " << prefix.string() << "/uwsgi;\n"
                        << "  scgi_temp_path " << prefix.string() << "/scgi;\n"
                        << "  server { listen 127.0.0.1:" << port_ << "; root " << root.string()
                        << "; }\n}\n";
    const std::string p = prefix.string(), c = conf.string(), e = (prefix / "logs/error.log").string();
    const char* argv[] = {"/usr/sbin/nginx", "-p", p.c_str(), "-c", c.c_str(), "-e", e.c_str(), nullptr};
    if (posix_spawn(&pid_, argv[0], nullptr, nullptr, const_cast<char**>(argv), environ) != 0) {
      pid_ = -1;
      ADD_FAILURE() << "cannot start /usr/sbin/nginx (scripts/setup installs nginx-light)";
      return;
    }
    for (int i = 0; i < 200; ++i) {  // up to 10 s for it to listen
      asio::io_context io;
      asio::ip::tcp::socket s(io);
      boost::system::error_code ec;
      s.connect({asio::ip::make_address("127.0.0.1"), port_}, ec);
      if (!ec) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ADD_FAILURE() << "nginx did not listen on port " << port_;
  }
  ~Nginx() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
  }
  uint16_t port() const { return port_; }

 private:
  pid_t pid_ = -1;
  uint16_t port_ = 0;
};

}  // namespace lodstream::test
