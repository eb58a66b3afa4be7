// `lodstream link`: the link emulator (DESIGN.md, Link emulation), a shaping TCP proxy on loopback.
#include <cstdio>
#include <memory>

#include "command.hpp"
#include "net/link_proxy.hpp"

namespace lodstream::cli {
namespace {

struct LinkOptions {
  std::string listen, to, bandwidth = "10mbit", rtt = "80ms", jitter = "0ms";
  uint64_t seed = 1;
};

int run_link(const LinkOptions& opt) {
  auto [listen_host, listen_port] = parse_host_port(opt.listen, "--listen");
  auto [to_host, to_port] = parse_host_port(opt.to, "--to");
  LinkSettings settings;
  settings.bandwidth_bps = parse_bandwidth(opt.bandwidth, "--bandwidth");
  settings.rtt_s = parse_duration(opt.rtt, "--rtt");
  settings.jitter_s = parse_duration(opt.jitter, "--jitter");
  settings.seed = opt.seed;
  StopSignals stop;  // before the worker threads start
  LinkProxy proxy(listen_host, listen_port, to_host, to_port, settings);
  std::printf("link: listening on %s:%u, forwarding to %s:%u at %.6g Mbit/s, RTT %.6g ms, jitter %.6g ms\n",
              listen_host.c_str(), proxy.port(), to_host.c_str(), to_port, settings.bandwidth_bps / 1e6,
              settings.rtt_s * 1e3, settings.jitter_s * 1e3);
  std::fflush(stdout);
  int signal = stop.wait();
  std::fprintf(stderr, "link: stopped by signal %d\n", signal);
  return 0;
}

const bool registered = register_command(
    {"link", "emulate a slow, distant link: a TCP proxy shaping bandwidth and round-trip time",
     [](CLI::App& sub) {
       auto opt = std::make_shared<LinkOptions>();
       sub.add_option("--listen", opt->listen, "address to listen on, HOST:PORT (port 0 picks a free one)")
           ->required();
       sub.add_option("--to", opt->to, "address to forward to, HOST:PORT")->required();
       sub.add_option("--bandwidth", opt->bandwidth, "each direction: 10mbit, 500kbit, 1gbit")
           ->capture_default_str();
       sub.add_option("--rtt", opt->rtt, "round-trip time added: 80ms, 0.2s")->capture_default_str();
       sub.add_option("--jitter", opt->jitter, "one-way delay varies uniformly within +-jitter (order kept)")
           ->capture_default_str();
       sub.add_option("--seed", opt->seed, "seed of the jitter sequence")->capture_default_str();
       sub.footer(
           "Shapes each direction with a token bucket (the bandwidth) and a delay line (half the RTT each "
           "way).\n"
           "Runs until SIGINT or SIGTERM. Example:\n"
           "  lodstream link --listen 127.0.0.1:9000 --to 127.0.0.1:8080 --bandwidth 10mbit --rtt 80ms");
       return [opt] { return run_link(*opt); };
     }});

}  // namespace
}  // namespace lodstream::cli
