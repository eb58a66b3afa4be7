// bench_link_probe: measures what a TCP path really delivers, to check `lodstream link` (and the kernel's tbf
// qdisc, for comparison) against their settings. Used by bench/link-vs-tbf; not part of lodstream itself.
//   bench_link_probe serve ADDR PORT            sink: echoes ping bytes, times bulk transfers at the receiver
//   bench_link_probe measure ADDR PORT BYTES    prints {"rtt_ms": median of 20 pings, "throughput_mbit": ...}
// Hand-written on POSIX sockets: a measurement tool small enough that no library is needed.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

namespace {
using Clock = std::chrono::steady_clock;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "bench_link_probe: %s: %s\n", what, std::strerror(errno));
  std::exit(1);
}

sockaddr_in address(const char* host, int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(uint16_t(port));
  if (inet_pton(AF_INET, host, &a.sin_addr) != 1) fail("bad IPv4 address");
  return a;
}

bool read_exact(int fd, void* p, size_t n) {
  auto* c = static_cast<char*>(p);
  while (n > 0) {
    ssize_t r = read(fd, c, n);
    if (r <= 0) return false;
    c += r, n -= size_t(r);
  }
  return true;
}

void write_exact(int fd, const void* p, size_t n) {
  auto* c = static_cast<const char*>(p);
  while (n > 0) {
    ssize_t r = write(fd, c, n);
    if (r <= 0) fail("write");
    c += r, n -= size_t(r);
  }
}

// One connection: the first byte says what it is. 'P': echo each byte until end of stream. 'B': read until
// end of stream, then answer with the receiver's throughput (bits per second between first and last byte).
void session(int fd) {
  char mode = 0;
  if (!read_exact(fd, &mode, 1)) return close(fd), void();
  if (mode == 'P') {
    char c;
    while (read_exact(fd, &c, 1)) write_exact(fd, &c, 1);
  } else if (mode == 'B') {
    std::vector<char> buf(1 << 16);
    size_t total = 0;
    Clock::time_point first{}, last{};
    for (ssize_t r; (r = read(fd, buf.data(), buf.size())) > 0;) {
      if (total == 0) first = Clock::now();
      total += size_t(r);
      last = Clock::now();
    }
    double bps = 8.0 * double(total) / std::chrono::duration<double>(last - first).count();
    write_exact(fd, &bps, sizeof bps);
  }
  close(fd);
}

int connect_to(const char* host, int port) {
  int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a = address(host, port);
  if (connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) fail("connect");
  int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  return fd;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::strcmp(argv[1], "serve") == 0) {
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a = address(argv[2], std::atoi(argv[3]));
    if (bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || listen(fd, 16) != 0) fail("bind");
    for (;;) {
      int c = accept(fd, nullptr, nullptr);
      if (c >= 0) std::thread(session, c).detach();
    }
  }
  if (argc == 5 && std::strcmp(argv[1], "measure") == 0) {
    const char* host = argv[2];
    int port = std::atoi(argv[3]);
    size_t bytes = std::strtoull(argv[4], nullptr, 10);
    int fd = connect_to(host, port);
    write_exact(fd, "P", 1);
    std::vector<double> rtts;
    for (int i = 0; i < 21; ++i) {
      char c = 'x';
      auto t0 = Clock::now();
      write_exact(fd, &c, 1);
      if (!read_exact(fd, &c, 1)) fail("ping");
      rtts.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    close(fd);
    std::sort(rtts.begin(), rtts.end());
    fd = connect_to(host, port);
    std::vector<char> data(bytes + 1, 'b');
    data[0] = 'B';
    write_exact(fd, data.data(), data.size());
    shutdown(fd, SHUT_WR);
    double bps = 0;
    if (!read_exact(fd, &bps, sizeof bps)) fail("bulk");
    close(fd);
    std::printf("{\"rtt_ms\": %.2f, \"throughput_mbit\": %.3f, \"bytes\": %zu}\n", rtts[rtts.size() / 2],
                bps / 1e6, bytes);
    return 0;
  }
  std::fprintf(stderr, "usage: bench_link_probe serve ADDR PORT | measure ADDR PORT BYTES\n");
  return 1;
}
