// `lodstream inspect SCENE.lods [--json] [--verify] [--cuts N] [--parts]`: what a package holds (nodes,
// pages, levels, bytes, per-level counts and errors; with --parts, each level's bytes per node part, raw and
// after zstd, and vertices per triangle: package/size_account.hpp; and the index's bytes per record field:
// package/index_account.hpp) and, with --verify, whether every
// invariant of DESIGN.md's Data model holds: the content hash, monotonic errors (a node's parents' pair is
// its parents' own pair and at least its own), containing spheres, every page and node decodes and matches
// its record, and crack-free cuts: for N random eyes and thresholds per representation, the cut chosen by the
// cut rule, welded by decoded position, has exactly the boundary edges of the full-resolution (level-0)
// surface; and for an HLOD (check_hlod): proxy object sets nest (an inner proxy's objects are the disjoint
// union of its children's, the root's cover every object it lists once per leaf) and a leaf proxy bounds its
// objects' roots (error at least theirs in world units, sphere containing theirs and the object's bounds);
// for a progressive mesh (check_progressive), its steps form one chain and every prefix assembles into a
// valid mesh. Every embedded texture (blob) must decode as an image. Exits 1 naming the first violation.
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>

#include "command.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "hierarchy/bounding_sphere.hpp"
#include "hierarchy/cut.hpp"
#include "package/index_account.hpp"
#include "package/progressive_prefix.hpp"
#include "package/reader.hpp"
#include "package/records.hpp"
#include "package/size_account.hpp"
#include "schedule/cut.hpp"

namespace lodstream::cli {
namespace {

using namespace package;

struct InspectArgs {
  std::string package;
  bool json = false, verify = false, parts = false;
  int cuts = 32;
};

bool same_sphere(const Sphere& a, const Sphere& b) {
  return a.center == b.center && a.radius == b.radius;
}

// The first violation of the record invariants, or "".
std::string check_records(const std::vector<NodeRecord>& nodes) {
  for (uint32_t id = 0; id < nodes.size(); ++id) {
    const NodeRecord& n = nodes[id];
    const std::string where = "node " + std::to_string(id) + ": ";
    if (!(n.parent_error >= n.error)) return where + "parents' error is below its own (not monotonic)";
    if (n.parents.empty() != std::isinf(n.parent_error))
      return where + "parents' error must be infinite exactly when it has no parents";
    if (!n.parents.empty() && !sphere_contains(n.parent_sphere, n.sphere))
      return where + "parents' sphere does not contain its own";
    for (uint32_t p : n.parents)
      if (nodes[p].error != n.parent_error || !same_sphere(nodes[p].sphere, n.parent_sphere))
        return where + "parent " + std::to_string(p) +
               "'s (error, sphere) differs from its stored parents' pair";
    for (uint32_t c : n.children)
      if (nodes[c].parent_error != n.error || !same_sphere(nodes[c].parent_sphere, n.sphere))
        return where + "child " + std::to_string(c) + "'s parents' pair differs from this node's own pair";
  }
  return "";
}

// The first violation of the HLOD invariants (header), or "".
std::string check_hlod(const PackageScene& scene, const std::vector<NodeRecord>& nodes) {
  for (uint32_t r = 0; r < scene.representations.size(); ++r) {
    const Representation& rep = scene.representations[r];
    if (rep.kind != RepresentationKind::hlod) continue;
    std::vector<uint32_t> leaf_of(scene.objects.size(), kNone);
    std::vector<uint32_t> stack(rep.roots.begin(), rep.roots.end());
    std::vector<uint8_t> seen(nodes.size(), 0);
    while (!stack.empty()) {
      const uint32_t id = stack.back();
      stack.pop_back();
      const NodeRecord& n = nodes[id];
      const std::string where = "HLOD node " + std::to_string(id) + ": ";
      if (seen[id]++) return where + "is reached twice (not a tree)";
      if (n.kind != NodeKind::hlod_proxy || n.representation != r)
        return where + "is not a proxy of its HLOD";
      if (n.objects.empty() || !std::is_sorted(n.objects.begin(), n.objects.end()) ||
          std::adjacent_find(n.objects.begin(), n.objects.end()) != n.objects.end())
        return where + "its objects are not a non-empty sorted set";
      if (!n.children.empty()) {
        std::vector<uint32_t> below;
        for (uint32_t c : n.children) {
          below.insert(below.end(), nodes[c].objects.begin(), nodes[c].objects.end());
          stack.push_back(c);
        }
        std::sort(below.begin(), below.end());
        if (below != n.objects) return where + "its objects are not the disjoint union of its children's";
        continue;
      }
      for (uint32_t o : n.objects) {
        if (leaf_of[o] != kNone)
          return where + "object " + std::to_string(o) + " is also under leaf " + std::to_string(leaf_of[o]);
        leaf_of[o] = id;
        const ObjectRecord& object = scene.objects[o];
        const double scale = schedule::max_scale(object.transform);
        const schedule::WorldSphere os = schedule::object_sphere(scene, o);
        if (!sphere_contains(n.sphere, Sphere{glm::vec3(os.center), float(os.radius)}))
          return where + "its sphere does not contain object " + std::to_string(o) + "'s bounds";
        for (uint32_t root : scene.representations[object.representation].roots) {
          const NodeRecord& rr = nodes[root];
          const schedule::WorldSphere ws = schedule::to_world(rr.sphere, object.transform, scale);
          if (double(n.error) < double(rr.error) * scale)
            return where + "its error is below object " + std::to_string(o) + "'s root " +
                   std::to_string(root);
          if (!sphere_contains(n.sphere, Sphere{glm::vec3(ws.center), float(ws.radius)}))
            return where + "its sphere does not contain object " + std::to_string(o) + "'s root " +
                   std::to_string(root);
        }
      }
    }
  }
  return "";
}

// The first violation of the progressive-mesh invariants, or "": each progressive representation is one chain
// of progressive steps from its root (step k's child is step k+1, whose only parent is k; errors
// non-increasing along it, which check_records' pairs imply), covering all of its nodes; and every prefix
// (steps 0..j) assembles (package/progressive_prefix.hpp: steps contiguous, every corner resolves below the
// prefix's vertex count, no degenerate triangle) with its vertices inside the steps' sphere.
std::string check_progressive(PackageReader& reader, const std::vector<NodeRecord>& nodes) {
  const PackageScene& scene = reader.scene();
  std::vector<size_t> members(scene.representations.size(), 0);
  for (const NodeRecord& n : nodes) ++members[n.representation];
  for (uint32_t r = 0; r < scene.representations.size(); ++r) {
    const Representation& rep = scene.representations[r];
    if (rep.kind != RepresentationKind::progressive_mesh) continue;
    const std::string where = "progressive representation " + std::to_string(r) + ": ";
    if (rep.roots.size() != 1) return where + "must have one root (step 0)";
    std::vector<DecodedNode> steps;
    for (uint32_t id = rep.roots[0], previous = kNone;;) {
      const NodeRecord& n = nodes[id];
      const std::string at = where + "node " + std::to_string(id) + ": ";
      if (n.kind != NodeKind::progressive_step || n.representation != r)
        return at + "is not a progressive step of it";
      if (n.parents != (previous == kNone ? std::vector<uint32_t>{} : std::vector<uint32_t>{previous}))
        return at + "its parent is not the step before it";
      if (n.children.size() > 1) return at + "has more than one next step";
      if (steps.size() >= members[r]) return at + "the chain of steps loops";
      try {
        steps.push_back(reader.load_node(id));
        std::vector<const DecodedNode*> prefix;
        for (const DecodedNode& s : steps) prefix.push_back(&s);
        const Mesh m = assemble_prefix(prefix, reader.source().name());
        for (const glm::vec3& v : m.positions)
          if (glm::length(v - n.sphere.center) > n.sphere.radius * 1.00001f + 2.0f * rep.grid.step)
            return at + "a vertex of its prefix lies outside the sphere";
      } catch (const Error& e) {
        return at + e.what();
      }
      if (n.children.empty()) break;
      previous = id, id = n.children[0];
    }
    if (steps.size() != members[r])
      return where + "its chain of steps leaves out " + std::to_string(members[r] - steps.size()) + " nodes";
  }
  return "";
}

struct Summary {
  nlohmann::json json;
  std::string text;
};

int run_inspect(const InspectArgs& args) {
  if (args.cuts < 0) throw Error("--cuts: must be >= 0");
  PackageReader reader = PackageReader::open(args.package);
  const RootIndex& root = reader.root();
  std::vector<NodeRecord> nodes(reader.node_count());
  for (uint32_t id = 0; id < nodes.size(); ++id) nodes[id] = reader.node(id);

  uint32_t levels = 0;
  for (const Representation& r : root.scene.representations) levels = std::max(levels, r.levels);
  struct Level {
    size_t nodes = 0, triangles = 0, raw_bytes = 0;  // raw: node bytes before the pages' zstd
    float min_error = INFINITY, max_error = 0.0f;
  };
  std::map<uint32_t, Level> per_level;
  std::map<uint32_t, Level> hlod_levels;  // the HLOD's proxies alone (also counted in per_level)
  size_t stored_triangles = 0;
  for (uint32_t id = 0; id < nodes.size(); ++id) {
    const NodeRecord& n = nodes[id];
    const bool proxy = n.representation < root.scene.representations.size() &&
                       root.scene.representations[n.representation].kind == RepresentationKind::hlod;
    for (Level* l : {&per_level[n.level], proxy ? &hlod_levels[n.level] : nullptr}) {
      if (!l) continue;
      ++l->nodes, l->triangles += n.triangles;
      // A record's bytes once (its clusters are consecutive ids sharing them).
      if (id == 0 || n.page != nodes[id - 1].page || n.offset != nodes[id - 1].offset) l->raw_bytes += n.size;
      l->min_error = std::min(l->min_error, n.error), l->max_error = std::max(l->max_error, n.error);
    }
    stored_triangles += n.triangles;
  }
  const uint64_t bytes = reader.header().file_size;
  uint64_t texture_bytes = 0;
  for (const Range& b : root.blobs) texture_bytes += b.size;

  std::vector<LevelAccount> account;
  IndexAccount index_account;
  if (args.parts) account = account_sizes(reader), index_account = account_index(reader);

  std::string violation;
  if (args.verify) {
    reader.verify();  // header = trailer, content hash (throws on mismatch)
    violation = check_records(nodes);
    if (violation.empty()) violation = check_hlod(root.scene, nodes);
    // Decode every page and node; weld each representation's nodes by decoded position.
    std::vector<hierarchy::SurfaceWelder> welders(root.scene.representations.size());
    std::vector<std::vector<uint32_t>> welded(nodes.size());
    std::vector<std::vector<uint32_t>> on_page(root.pages.size());
    for (uint32_t id = 0; id < nodes.size(); ++id)
      if (nodes[id].encoding == NodeEncoding::codec) on_page[nodes[id].page].push_back(id);
    const size_t batch = 64;
    for (size_t first = 0; first < on_page.size() && violation.empty(); first += batch) {
      const size_t end = std::min(on_page.size(), first + batch);
      std::vector<std::vector<DecodedNode>> decoded(end - first);
      tbb::parallel_for(first, end, [&](size_t p) {
        const std::vector<uint8_t> page = reader.read_page(uint32_t(p));
        DecodedNode record;  // the record of the previous node (its clusters are consecutive ids)
        uint32_t record_offset = UINT32_MAX;
        for (uint32_t id : on_page[p]) {
          const NodeRecord& n = nodes[id];
          const std::string where = args.package + ": node " + std::to_string(id);
          if (n.offset != record_offset) {
            record = reader.codec().decode(std::span<const uint8_t>(page).subspan(n.offset, n.size),
                                           root.scene.representations[n.representation].grid, where);
            record_offset = n.offset;
          }
          if (record_clusters(record) == 1 && n.cluster == 0) {  // a node alone (progressive steps too)
            decoded[p - first].push_back(std::move(record));
            record_offset = UINT32_MAX;
          } else {
            decoded[p - first].push_back(extract_cluster(record, n.cluster, where));
          }
        }
      });
      for (size_t p = first; p < end && violation.empty(); ++p)
        for (size_t k = 0; k < on_page[p].size(); ++k) {
          const uint32_t id = on_page[p][k];
          const Mesh& m = decoded[p - first][k].mesh;
          if (m.triangle_count() != nodes[id].triangles) {
            violation = "node " + std::to_string(id) + ": decoded triangle count differs from its record";
            break;
          }
          // Tolerance: the finest grid's rounding (level-0 spheres bound the unquantized positions).
          for (const glm::vec3& v : m.positions)
            if (glm::length(v - nodes[id].sphere.center) >
                nodes[id].sphere.radius * 1.00001f +
                    2.0f * root.scene.representations[nodes[id].representation].grid.step) {
              violation = "node " + std::to_string(id) + ": a decoded vertex lies outside its sphere";
              break;
            }
          // (A progressive step's corners may lie in later steps: its prefixes are checked below.)
          if (nodes[id].kind != NodeKind::progressive_step)
            welded[id] = welders[nodes[id].representation].weld(m);
        }
    }
    // Every embedded texture decodes as an image.
    for (uint32_t b = 0; b < root.blobs.size() && violation.empty(); ++b) {
      try {
        decode_image(reader.read_blob(b), "blob " + std::to_string(b));
      } catch (const Error& e) {
        violation = e.what();
      }
    }
    if (violation.empty()) violation = check_progressive(reader, nodes);
    // Crack-free cuts per cluster DAG.
    std::mt19937 rng(12345);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (uint32_t r = 0; r < root.scene.representations.size() && violation.empty(); ++r) {
      const Representation& rep = root.scene.representations[r];
      if (rep.kind != RepresentationKind::cluster_dag) continue;
      std::vector<uint32_t> members;
      std::vector<const std::vector<uint32_t>*> finest;
      for (uint32_t id = 0; id < nodes.size(); ++id)
        if (nodes[id].representation == r && nodes[id].kind == NodeKind::cluster) {
          members.push_back(id);
          if (nodes[id].level == 0) finest.push_back(&welded[id]);
        }
      const std::vector<uint64_t> reference = hierarchy::boundary_edges(finest);
      const glm::vec3 centre = rep.bounds.center();
      const double radius = std::max(1e-6f, 0.5f * rep.bounds.diagonal());
      for (int i = 0; i < args.cuts && violation.empty(); ++i) {
        hierarchy::CutView view;
        const glm::dvec3 dir(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
        view.eye = glm::dvec3(centre) + glm::normalize(dir) * radius * (0.2 + 20.0 * u(rng));
        const double tau = std::pow(10.0, -1.0 + 3.5 * u(rng));
        std::vector<const std::vector<uint32_t>*> cut;
        for (uint32_t id : members) {
          const NodeRecord& n = nodes[id];
          if (hierarchy::in_cut(n.error, n.sphere, n.parent_error, n.parent_sphere, view, tau))
            cut.push_back(&welded[id]);
        }
        const std::string diff = cut.empty() ? std::string("the cut is empty")
                                             : hierarchy::compare_boundaries(hierarchy::boundary_edges(cut),
                                                                             reference, welders[r]);
        if (!diff.empty()) {
          char eye[160];
          std::snprintf(eye, sizeof eye, "eye (%g,%g,%g), tau %g px: ", view.eye.x, view.eye.y, view.eye.z,
                        tau);
          violation =
              "representation " + std::to_string(r) + ", cut " + std::to_string(i) + " at " + eye + diff;
        }
      }
    }
  }

  if (args.json) {
    auto levels_json = [](const std::map<uint32_t, Level>& levels) {
      nlohmann::json out = nlohmann::json::array();
      for (const auto& [l, s] : levels)
        out.push_back({{"level", l},
                       {"nodes", s.nodes},
                       {"triangles", s.triangles},
                       {"raw_bytes", s.raw_bytes},
                       {"min_error", s.min_error},
                       {"max_error", s.max_error}});
      return out;
    };
    const nlohmann::json level_json = levels_json(per_level);
    nlohmann::json out = {{"nodes", nodes.size()},
                          {"pages", root.pages.size()},
                          {"levels", levels},
                          {"bytes", bytes},
                          {"input_triangles", root.scene.input_triangles},
                          {"stored_triangles", stored_triangles},
                          {"objects", root.scene.objects.size()},
                          {"representations", root.scene.representations.size()},
                          {"root_nodes", root.root_nodes.size()},
                          {"index_pages", root.index_pages.size()},
                          {"textures", root.blobs.size()},
                          {"texture_bytes", texture_bytes},
                          {"per_level", level_json},
                          {"hlod_levels", levels_json(hlod_levels)}};
    if (args.parts) {
      nlohmann::json parts = nlohmann::json::array();
      for (const LevelAccount& a : account) {
        nlohmann::json raw, compressed;
        for (uint32_t p = 0; p < kNodeParts; ++p) {
          raw[node_part_name(NodePart(p))] = a.parts[p].raw;
          compressed[node_part_name(NodePart(p))] = a.parts[p].compressed;
        }
        parts.push_back({{"level", a.level},
                         {"nodes", a.nodes},
                         {"triangles", a.triangles},
                         {"vertices", a.vertices},
                         {"page_bytes", std::llround(a.page_bytes)},
                         {"raw", raw},
                         {"compressed", compressed}});
      }
      out["parts"] = parts;
      nlohmann::json raw, compressed;
      for (size_t f = 0; f < kIndexFields; ++f) {
        raw[kIndexFieldNames[f]] = index_account.raw[f];
        compressed[kIndexFieldNames[f]] = index_account.compressed[f];
      }
      out["index_parts"] = {{"records", index_account.records},
                            {"root_stored", index_account.root_stored},
                            {"pages_stored", index_account.pages_stored},
                            {"raw", raw},
                            {"compressed", compressed}};
    }
    if (args.verify) {
      out["verified"] = violation.empty();
      out["violation"] = violation.empty() ? nlohmann::json(nullptr) : nlohmann::json(violation);
    }
    print_json(out);
  } else {
    std::printf(
        "%s: %zu nodes, %zu pages, %u levels, %llu bytes, %llu input triangles (%zu stored), %zu objects\n",
        args.package.c_str(), nodes.size(), root.pages.size(), levels, (unsigned long long)bytes,
        (unsigned long long)root.scene.input_triangles, stored_triangles, root.scene.objects.size());
    if (!root.blobs.empty())
      std::printf("  %zu embedded textures, %llu bytes\n", root.blobs.size(),
                  (unsigned long long)texture_bytes);
    for (const auto& [l, s] : per_level)
      std::printf("  level %2u: %7zu nodes %10zu triangles  error %.4g .. %.4g\n", l, s.nodes, s.triangles,
                  s.min_error, s.max_error);
    if (!hlod_levels.empty()) std::printf("  of which HLOD proxies (world units):\n");
    for (const auto& [l, s] : hlod_levels)
      std::printf("  level %2u: %7zu proxies %8zu triangles  error %.4g .. %.4g\n", l, s.nodes, s.triangles,
                  s.min_error, s.max_error);
    if (args.parts) {
      std::printf(
          "  bytes per stored triangle by part, raw / alone after zstd (inspect --help):\n  level  vert/tri");
      for (uint32_t p = 0; p < kNodeParts; ++p) std::printf(" %15s", node_part_name(NodePart(p)));
      std::printf("  pages after zstd\n");
      for (const LevelAccount& a : account) {
        const double t = double(std::max<uint64_t>(1, a.triangles));
        std::printf("  %5u  %8.3f", a.level, double(a.vertices) / t);
        for (const PartBytes& b : a.parts) std::printf("   %5.2f / %5.2f", b.raw / t, b.compressed / t);
        std::printf("  %6.3f\n", a.page_bytes / t);
      }
      const IndexAccount& x = index_account;
      const double r = double(std::max<uint64_t>(1, x.records));
      std::printf(
          "  index: %llu records, root index %llu B and index pages %llu B stored (%.2f B/record);\n"
          "  bytes per record by field, raw / alone after zstd:\n",
          (unsigned long long)x.records, (unsigned long long)x.root_stored,
          (unsigned long long)x.pages_stored, double(x.root_stored + x.pages_stored) / r);
      for (size_t f = 0; f < kIndexFields; ++f)
        std::printf("  %18s  %6.2f / %5.2f\n", kIndexFieldNames[f], x.raw[f] / r, x.compressed[f] / r);
    }
    if (args.verify && violation.empty())
      std::printf("verified: every invariant holds (%d cuts per DAG)\n", args.cuts);
  }
  if (!violation.empty()) {
    std::fprintf(stderr, "lodstream: inspect: %s: verify failed: %s\n", args.package.c_str(),
                 violation.c_str());
    return 1;
  }
  return 0;
}

const bool registered = register_command(
    {"inspect", "summarize a package (.lods) and, with --verify, check every invariant", [](CLI::App& sub) {
       auto args = std::make_shared<InspectArgs>();
       sub.add_option("SCENE", args->package, "the package (.lods)")->required();
       sub.add_flag("--verify", args->verify,
                    "check content hash, monotonic errors, containing spheres, decoding of every node and "
                    "crack-free cuts; exit 1 naming the first violation");
       sub.add_flag(
           "--parts", args->parts,
           "also each level's vertices and bytes per node part (header, positions, normals, "
           "attributes, locked, connectivity), raw and compressed alone by zstd in page-sized chunks, "
           "and the stored page bytes per level (JSON key parts); and the index's bytes per record field "
           "(JSON key index_parts)");
       sub.add_option("--cuts", args->cuts, "random cuts checked per cluster DAG with --verify (default 32)");
       sub.add_flag("--json", args->json,
                    "print one JSON object: nodes, pages, levels, bytes, input_triangles, per_level, "
                    "hlod_levels (the HLOD's "
                    "proxies alone), verified");
       return [args] { return run_inspect(*args); };
     }});

}  // namespace
}  // namespace lodstream::cli
