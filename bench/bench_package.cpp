// bench_package: size and speed of the .lods package on a real mesh cut into meshlets (the finest level of a
// cluster DAG: 64 vertices / 124 triangles, positions on a 2^-14 grid of the diagonal, octahedral normals).
//
//   bench_package [--mesh=FILE] [--normal-bits=N] [--zstd-level=L] [--no-sizes] [google benchmark flags]
//
// Every figure is measured for codec 1 (meshoptimizer's codecs), codec 2 (predicted positions and normals)
// and codec 3 (traversal-ordered connectivity, predicted positions and normals) side by side in one run
// (benchmark argument = codec id). Before the timings it prints the size table: bytes
// per triangle of the whole package and where they go (positions, normals, UVs, connectivity, index), each
// measured after zstd by encoding with and without the attribute. Timings report triangles per second on one
// core: encode (codec), write (codec + zstd + file), decode (checksum + zstd + codec, from pages in memory)
// and decode of the codec alone.
#include <benchmark/benchmark.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <string>

#include "core/error.hpp"
#include "io/import.hpp"
#include "package/reader.hpp"
#include "package/records.hpp"
#include "package/writer.hpp"

namespace {

using namespace lodstream;
using namespace lodstream::package;

std::filesystem::path g_mesh_file = LODSTREAM_SOURCE_DIR "/data/refined_elephant.off";
uint32_t g_normal_bits = 10;
int g_zstd_level = WriterOptions{}.zstd_level;
bool g_sizes = true;  // --no-sizes: timings only (e.g. under callgrind, which the zstd-19 sizes would slow)

struct Meshlets {
  Mesh mesh;  // the whole input mesh (all objects' meshes merged)
  PositionGrid grid;
  std::vector<Mesh> chunks;
  std::vector<std::vector<uint8_t>> locked;  // vertices shared with another meshlet
  size_t triangles = 0;
};

Mesh merged(const Scene& scene) {
  Mesh out;
  for (const Object& o : scene.objects) {
    const Mesh& m = scene.meshes[o.mesh];
    const uint32_t base = uint32_t(out.positions.size());
    for (const glm::vec3& p : m.positions)
      out.positions.push_back(glm::vec3(o.transform * glm::vec4(p, 1.0f)));
    if (m.has_normals()) out.normals.insert(out.normals.end(), m.normals.begin(), m.normals.end());
    if (m.has_uvs()) out.uvs.insert(out.uvs.end(), m.uvs.begin(), m.uvs.end());
    for (uint32_t i : m.indices) out.indices.push_back(base + i);
  }
  if (out.normals.size() != out.positions.size()) out.normals.clear();
  if (out.uvs.size() != out.positions.size()) out.uvs.clear();
  return out;
}

const Meshlets& meshlets() {
  static const Meshlets m = [] {
    Meshlets r;
    r.mesh = merged(import_model(g_mesh_file));
    r.grid = PositionGrid::for_bounds(r.mesh.bounds(), 14);
    const size_t max_v = 64, max_t = 124;
    std::vector<meshopt_Meshlet> ml(meshopt_buildMeshletsBound(r.mesh.indices.size(), max_v, max_t));
    std::vector<unsigned> mv(ml.size() * max_v);
    std::vector<unsigned char> mt(ml.size() * max_t * 3);
    ml.resize(meshopt_buildMeshlets(ml.data(), mv.data(), mt.data(), r.mesh.indices.data(),
                                    r.mesh.indices.size(), &r.mesh.positions[0].x, r.mesh.vertex_count(),
                                    sizeof(glm::vec3), max_v, max_t, 0.0f));
    std::vector<uint32_t> owners(r.mesh.vertex_count(), 0);
    for (const meshopt_Meshlet& l : ml) {
      for (unsigned v = 0; v < l.vertex_count; ++v) ++owners[mv[l.vertex_offset + v]];
    }
    for (const meshopt_Meshlet& l : ml) {
      Mesh c;
      std::vector<uint8_t> locked;
      for (unsigned v = 0; v < l.vertex_count; ++v) {
        const uint32_t src = mv[l.vertex_offset + v];
        c.positions.push_back(r.mesh.positions[src]);
        if (r.mesh.has_normals()) c.normals.push_back(r.mesh.normals[src]);
        if (r.mesh.has_uvs()) c.uvs.push_back(r.mesh.uvs[src]);
        locked.push_back(owners[src] > 1);
      }
      for (unsigned i = 0; i < l.triangle_count * 3; ++i) c.indices.push_back(mt[l.triangle_offset + i]);
      r.triangles += l.triangle_count;
      r.chunks.push_back(std::move(c));
      r.locked.push_back(std::move(locked));
    }
    return r;
  }();
  return m;
}

enum Attributes { kPositions = 0, kNormals = 1, kUvs = 2, kAll = 3 };

std::vector<std::vector<uint8_t>> encode_all(const Meshlets& m, int attributes, const NodeCodec& codec) {
  std::vector<std::vector<uint8_t>> out;
  out.reserve(m.chunks.size());
  for (size_t i = 0; i < m.chunks.size(); ++i) {
    Mesh stripped;
    const Mesh* mesh = &m.chunks[i];
    if (attributes != kAll) {
      stripped = m.chunks[i];
      if (!(attributes & kNormals)) stripped.normals.clear();
      if (!(attributes & kUvs)) stripped.uvs.clear();
      mesh = &stripped;
    }
    NodeGeometry g;
    g.mesh = mesh;
    g.locked = m.locked[i];
    g.normal_bits = g_normal_bits;
    out.push_back(codec.encode(g, m.grid));
  }
  return out;
}

// Records (codec 3): each group of 8 consecutive meshlets (a page group) as one record, welded on their
// shared vertices (package/records.hpp).
constexpr size_t kRecordClusters = 8;
// Benchmark argument of codec 3 with such records (decoded one cluster after another in id order, as a
// client does: each record is decoded once, PackageReader keeping the last).
constexpr uint32_t kRecordsArg = 4;
std::vector<std::vector<uint8_t>> encode_records(const Meshlets& m, const NodeCodec& codec) {
  std::vector<std::vector<uint8_t>> out;
  for (size_t first = 0; first < m.chunks.size(); first += kRecordClusters) {
    const size_t end = std::min(m.chunks.size(), first + kRecordClusters);
    std::vector<const Mesh*> meshes;
    std::vector<std::span<const uint8_t>> locked;
    for (size_t i = first; i < end; ++i) meshes.push_back(&m.chunks[i]), locked.push_back(m.locked[i]);
    const RecordMesh record = weld_record(meshes, locked);
    NodeGeometry g;
    g.mesh = &record.mesh;
    g.normal_bits = g_normal_bits;
    g.cluster_triangles = record.cluster_triangles;
    out.push_back(codec.encode(g, m.grid));
  }
  return out;
}

WrittenPackage write_package(const Meshlets& m, const std::vector<std::vector<uint8_t>>& nodes,
                             const std::filesystem::path& file, int zstd_level, const NodeCodec& codec,
                             bool records_form = false) {
  WriterOptions options;
  options.zstd_level = zstd_level;
  options.codec = codec.id();
  PackageWriter writer(file, options);
  PackageScene scene;
  scene.input_triangles = m.triangles;
  scene.materials.resize(1);
  Representation rep;
  rep.bounds = m.mesh.bounds();
  rep.grid = m.grid;
  scene.representations.push_back(rep);
  scene.objects.push_back({"mesh", glm::mat4(1.0f), 0});
  std::vector<NodeRecord> records(m.chunks.size());
  for (uint32_t id = 0; id < m.chunks.size(); ++id)
    records[id].triangles = uint32_t(m.chunks[id].triangle_count());
  if (records_form) {
    for (uint32_t r = 0; r < nodes.size(); ++r) {
      std::vector<uint32_t> ids;
      for (uint32_t id = r * kRecordClusters;
           id < std::min<size_t>(m.chunks.size(), (r + 1) * kRecordClusters); ++id)
        ids.push_back(id);
      writer.add_record(ids, nodes[r]);
      writer.end_group();
    }
  } else {
    for (uint32_t id = 0; id < nodes.size(); ++id) {
      writer.add_node(id, nodes[id]);
      if (id % 8 == 7) writer.end_group();  // groups of 8 clusters, as a DAG group
    }
  }
  return writer.finish(scene, records, 0);
}

// CPU time of this thread: the machines are shared, so wall time measures the neighbours too.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::filesystem::path temp_file(const char* name) {
  return std::filesystem::temp_directory_path() / name;
}

// zstd-compressed bytes of the index streams alone, paged like the package (connectivity after zstd).
size_t connectivity_bytes(const std::vector<std::vector<uint8_t>>& nodes, int level, const NodeCodec& codec) {
  size_t total = 0;
  std::vector<uint8_t> page;
  auto flush = [&] {
    if (!page.empty()) total += zstd_compress(page, level).size();
    page.clear();
  };
  for (size_t i = 0; i < nodes.size(); ++i) {
    NodeSizeBreakdown b = codec.breakdown(nodes[i], "node");
    auto first = nodes[i].begin() + std::ptrdiff_t(b.header + b.vertices + b.locked);
    page.insert(page.end(), first, first + std::ptrdiff_t(b.indices));
    if (i % 8 == 7 && page.size() > 36 * 1024) flush();
  }
  flush();
  return total;
}

void print_sizes(const NodeCodec& codec) {
  const Meshlets& m = meshlets();
  std::printf("== codec %u\n", codec.id());
  const double T = double(m.triangles);
  std::printf("mesh %s: %zu triangles, %zu vertices, %zu meshlets (64 v / 124 t), normals %s, uvs %s\n",
              g_mesh_file.filename().c_str(), m.triangles, m.mesh.vertex_count(), m.chunks.size(),
              m.mesh.has_normals() ? "yes" : "no", m.mesh.has_uvs() ? "yes" : "no");
  std::printf(
      "grid step %.3g = 2^-14 of the diagonal; normals %u bits octahedral; zstd level %d; 48 KiB pages\n",
      double(m.grid.step), g_normal_bits, g_zstd_level);
  const auto all = encode_all(m, kAll, codec);
  size_t pre_zstd = 0, index_pre = 0, vertex_pre = 0, locked_pre = 0, header_pre = 0;
  for (const auto& n : all) {
    NodeSizeBreakdown b = codec.breakdown(n, "node");
    pre_zstd += n.size(), index_pre += b.indices, vertex_pre += b.vertices, locked_pre += b.locked,
        header_pre += b.header;
  }
  WrittenPackage full = write_package(m, all, temp_file("bench_all.lods"), g_zstd_level, codec);
  WrittenPackage pos =
      write_package(m, encode_all(m, kPositions, codec), temp_file("bench_pos.lods"), g_zstd_level, codec);
  WrittenPackage pos_n =
      write_package(m, encode_all(m, kNormals, codec), temp_file("bench_posn.lods"), g_zstd_level, codec);
  const size_t conn = connectivity_bytes(all, g_zstd_level, codec);
  std::printf("before zstd: %.3f B/tri (vertex stream %.3f, index stream %.3f, node headers %.3f)\n",
              pre_zstd / T, vertex_pre / T, index_pre / T, header_pre / T);
  std::printf(
      "package: %.3f B/tri = %llu bytes (pages %.3f, index pages %.3f, root index %llu B, trailer+header 128 "
      "B), %u pages\n",
      full.bytes / T, (unsigned long long)full.bytes, full.page_bytes / T, full.index_bytes / T,
      (unsigned long long)full.root_index_bytes, full.pages);
  std::printf(
      "  connectivity %.3f B/tri | positions (+node headers) %.3f | normals %.3f | uvs %.3f | index %.3f\n",
      conn / T, (double(pos.page_bytes) - conn) / T, (double(pos_n.page_bytes) - pos.page_bytes) / T,
      (double(full.page_bytes) - pos_n.page_bytes) / T, (full.bytes - full.page_bytes) / T);
  if (codec.max_record_clusters() >= kRecordClusters) {
    const WrittenPackage r =
        write_package(m, encode_records(m, codec), temp_file("bench_level.lods"), g_zstd_level, codec, true);
    std::printf("records of %zu meshlets (benchmark argument %u): %.3f B/tri = %llu bytes\n", kRecordClusters,
                kRecordsArg, r.bytes / T, (unsigned long long)r.bytes);
  }
  for (int level : {3, 9, 15, 19}) {
    const double t0 = thread_cpu_seconds();
    WrittenPackage w = write_package(m, all, temp_file("bench_level.lods"), level, codec);
    const double s = thread_cpu_seconds() - t0;
    std::printf(
        "  zstd level %2d: %.3f B/tri, pages written at %.2f M tri/s (zstd + file, CPU time, one core)\n",
        level, w.bytes / T, T / s * 1e-6);
  }
  std::fflush(stdout);
  for (const char* f : {"bench_all.lods", "bench_pos.lods", "bench_posn.lods", "bench_level.lods"}) {
    std::filesystem::remove(temp_file(f));
  }
}

void BM_Encode(benchmark::State& state) {
  const Meshlets& m = meshlets();
  const NodeCodec& codec = node_codec(uint32_t(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(encode_all(m, kAll, codec));
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(m.triangles));
}

void BM_EncodeAndWrite(benchmark::State& state) {
  const Meshlets& m = meshlets();
  const NodeCodec& codec = node_codec(uint32_t(state.range(0)));
  for (auto _ : state)
    write_package(m, encode_all(m, kAll, codec), temp_file("bench_write.lods"), g_zstd_level, codec);
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(m.triangles));
  std::filesystem::remove(temp_file("bench_write.lods"));
}

struct Loaded {
  std::unique_ptr<PackageReader> reader;
  std::vector<std::vector<uint8_t>> stored;  // every page as received from a link
  std::vector<std::vector<uint32_t>> nodes_of_page;
};

const Loaded& loaded(uint32_t id) {
  static std::map<uint32_t, Loaded> all;
  if (auto it = all.find(id); it != all.end()) return it->second;
  return all[id] = [id] {
    const bool records = id == kRecordsArg;
    const NodeCodec& codec = node_codec(records ? 3 : id);
    Loaded r;
    write_package(meshlets(),
                  records ? encode_records(meshlets(), codec) : encode_all(meshlets(), kAll, codec),
                  temp_file("bench_read.lods"), g_zstd_level, codec, records);
    r.reader = std::make_unique<PackageReader>(PackageReader::open(temp_file("bench_read.lods")));
    for (uint32_t p = 0; p < r.reader->root().pages.size(); ++p) {
      const Range& range = r.reader->root().pages[p];
      std::vector<uint8_t> bytes(range.size);
      r.reader->source().read(range.offset, bytes);
      r.stored.push_back(std::move(bytes));
    }
    r.nodes_of_page.resize(r.stored.size());
    for (uint32_t id = 0; id < r.reader->node_count(); ++id)
      r.nodes_of_page[r.reader->node(id).page].push_back(id);
    return r;
  }();
}

void BM_Decode(benchmark::State& state) {
  const Loaded& l = loaded(uint32_t(state.range(0)));
  for (auto _ : state) {
    for (size_t p = 0; p < l.stored.size(); ++p) {
      std::vector<uint8_t> raw = l.reader->unpack_page(uint32_t(p), l.stored[p]);
      for (uint32_t id : l.nodes_of_page[p]) benchmark::DoNotOptimize(l.reader->decode_node(id, raw));
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(meshlets().triangles));
}

void BM_DecodeCodecOnly(benchmark::State& state) {
  const Loaded& l = loaded(uint32_t(state.range(0)));
  std::vector<std::vector<uint8_t>> raw;
  for (size_t p = 0; p < l.stored.size(); ++p) raw.push_back(l.reader->unpack_page(uint32_t(p), l.stored[p]));
  for (auto _ : state) {
    for (size_t p = 0; p < raw.size(); ++p) {
      for (uint32_t id : l.nodes_of_page[p]) benchmark::DoNotOptimize(l.reader->decode_node(id, raw[p]));
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(meshlets().triangles));
}

BENCHMARK(BM_Encode)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EncodeAndWrite)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Decode)->Arg(1)->Arg(2)->Arg(3)->Arg(kRecordsArg)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeCodecOnly)->Arg(1)->Arg(2)->Arg(3)->Arg(kRecordsArg)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--mesh=", 0) == 0) {
      g_mesh_file = a.substr(7);
    } else if (a.rfind("--normal-bits=", 0) == 0) {
      g_normal_bits = uint32_t(std::stoi(a.substr(14)));
    } else if (a.rfind("--zstd-level=", 0) == 0) {
      g_zstd_level = std::stoi(a.substr(13));
    } else if (a == "--no-sizes") {
      g_sizes = false;
    } else {
      rest.push_back(argv[i]);
    }
  }
  int n = int(rest.size());
  benchmark::Initialize(&n, rest.data());
  try {
    for (uint32_t id : {1u, 2u, 3u})
      if (g_sizes) print_sizes(node_codec(id));
  } catch (const lodstream::Error& e) {
    std::fprintf(stderr, "bench_package: error: %s\n", e.what());
    return 1;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
