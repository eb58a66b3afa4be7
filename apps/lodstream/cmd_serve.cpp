// `lodstream serve`: serves packages over HTTP with byte ranges (DESIGN.md, Serving and the wire; addresses).
#include <cstdio>
#include <memory>
#include <set>

#include "command.hpp"
#include "core/error.hpp"
#include "net/http_server.hpp"
#include "package/reader.hpp"

namespace lodstream::cli {
namespace {

struct ServeOptions {
  std::vector<std::string> packages;
  std::string bind = "127.0.0.1";
  int port = 8080;
  int threads = 2;
};

int run_serve(const ServeOptions& opt) {
  if (opt.port < 0 || opt.port > 65535) throw Error("--port must be in 0..65535");
  if (opt.threads < 1 || opt.threads > 64) throw Error("--threads must be in 1..64");
  std::vector<ServedFile> files;
  std::set<std::string> names;
  for (const auto& path : opt.packages) {
    // Opening validates the header, trailer and root index: a broken file is refused before serving.
    auto reader = std::make_shared<const package::PackageReader>(package::PackageReader::open(path));
    std::string name = std::filesystem::path(path).stem().string() + ".lods";
    if (!names.insert(name).second) throw Error(path + ": another package is already served as /" + name);
    files.push_back({name, path, reader->header().content_hash.hex(), reader});
  }
  StopSignals stop;  // before the worker threads start
  HttpServer server(opt.bind, uint16_t(opt.port), files, opt.threads);
  std::string host = opt.bind.find(':') != std::string::npos ? "[" + opt.bind + "]" : opt.bind;
  std::printf("listening on http://%s:%u\n", host.c_str(), server.port());
  for (const auto& f : files)
    std::printf("  /%s  (%s), push at ws://%s:%u/%s\n", f.name.c_str(), f.path.c_str(), host.c_str(),
                server.port(), f.name.substr(0, f.name.size() - 5).c_str());
  std::fflush(stdout);
  int signal = stop.wait();
  std::fprintf(stderr, "serve: stopped by signal %d\n", signal);
  return 0;
}

const bool registered = register_command(
    {"serve", "serve packages over HTTP with byte ranges (pull) and WebSocket push streams",
     [](CLI::App& sub) {
       auto opt = std::make_shared<ServeOptions>();
       sub.add_option("packages", opt->packages, "SCENE.lods files, each served at /NAME.lods")
           ->required()
           ->check(CLI::ExistingFile);
       sub.add_option("--bind", opt->bind, "address to listen on (an IP address)")->capture_default_str();
       sub.add_option("--port", opt->port, "port; 0 picks a free one")->capture_default_str();
       sub.add_option("--threads", opt->threads, "threads serving connections")->capture_default_str();
       sub.footer(
           "Prints 'listening on http://ADDR:PORT' once ready; runs until SIGINT or SIGTERM. Each package "
           "is\n"
           "served with byte ranges (single, suffix, multiple), ETag = its content hash, If-Range honoured;\n"
           "its push stream is a WebSocket at /NAME (NAME = the file name without .lods).");
       return [opt] { return run_serve(*opt); };
     }});

}  // namespace
}  // namespace lodstream::cli
