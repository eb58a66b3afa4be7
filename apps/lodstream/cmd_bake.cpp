// `lodstream bake MODEL... -o SCENE.lods [--json] [--no-hlod] [--pm-max-triangles N]`: every mesh of the
// imported models becomes a cluster DAG (hierarchy/cluster_dag.hpp), or, with at most N triangles, a
// progressive mesh (hierarchy/progressive_steps.hpp: one node per prefix step, chained step k -> k+1, stored
// on the mesh's finest grid in vertex order with the full-resolution corners and chains of
// package/progressive_prefix.hpp), written into one .lods package (package/writer.hpp). Objects keep their
// transforms; objects that instance one mesh share its representation. Unless --no-hlod, a scene of two or
// more objects also gets an HLOD (hierarchy/hlod.hpp) over its objects' roots: one more representation, of
// kind hlod, whose nodes are world-space proxies listing the objects they stand for (and a white material
// "hlod-vertex-colors" when a proxy merges several materials).
//
// Node order (ids) and page order: first the HLOD's top levels (its root, children and grandchildren) and the
// roots of every representation (a progressive mesh's: step 0; the root index, enough for a first frame),
// then the other HLOD nodes, each parent's children as one page group, then each progressive mesh's steps 1..
// in order (a page group each), then, from the coarsest level down, the input clusters of each group
// simplification as one page group: refining a group needs exactly its input clusters, so they travel
// together (with a codec that stores records, consecutive groups of one level share a page group up to a
// record's clusters: join_groups). With a codec that stores records (codec 3), each page group of DAG
// clusters (joined groups' input clusters, a DAG's roots) is one record (package/records.hpp; several past
// NodeCodec::max_record_clusters()), one vertex pool for all its clusters, stored at the page group's finest
// precision. A group's records are encoded as soon as its input clusters are final, beside the next level's
// grouping (DagOptions::inputs_final), which leaves the other core idle; the roots' at the end.
//
// Precision (how the codec's position_shift is spent): level-0 clusters are stored on the finest grid of
// their mesh: 2^-b of its diagonal with b the fewest bits in [14, --max-grid-bits = 20] that keep its
// distinct positions distinct (PositionGrid::separating), and the mesh is snapped to that grid before its DAG
// is built (what still collides is welded). Measured on buildings.obj (near-duplicate vertices 1e-5 apart,
// which no grid separates): 20 bits verifies (200 random cuts) at 9.26 bytes per input triangle; 14 and 16
// bits with the snap weld its near-duplicates into non-manifold ground footprints whose cuts fail the
// boundary test. A coarser cluster made by a group of error e drops k low bits of its free vertices, k =
// floor(log2(e / (16 * step))) clamped to [0, 16], so that the rounding adds at most q(e) = sqrt(3)/2 * 2^k *
// step <= e / 16 * sqrt(3)/2; the stored error and sphere radius are raised by q(e). q is a non-decreasing
// function of e, so stored errors stay monotonic and spheres containing. Why 16 (measured with divisors 2, 4,
// 8, 16 and shift 0, at group ratio 0.5; bake, render at 1 px, bench stream gen:fly at 10 Mbit/s 80 ms): a
// larger shift saves bits on free vertices but costs 3k raw bits per locked vertex and raises stored errors,
// so clients refine deeper; against 4, divisor 16 gives elephant_1m a 0.6 % smaller package, 5-15 % fewer
// triangles at 1 px and PSNR at 1 / 2 / 5 s of 55.9 / 57.2 / 51.0 dB instead of 50.5 / 52.4 / 49.3 (push),
// refined_elephant +1.6 % bytes with PSNR 52.0 / 51.8 / 48.4 instead of 51.4 / 50.3 / 48.2. Vertices on the
// border of the group that made or consumes a cluster are flagged locked and decode exactly, so cuts stay
// crack-free (free vertices are shared only by clusters of one page group, stored at one shift:
// page_group_precision). HLOD proxies are stored on a 2^-14 grid of the scene's world bounds, shift 0; the
// rounding is part of their errors.
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <numeric>
#include <span>
#include <tuple>
#include <utility>

#include "bake_textures.hpp"
#include "command.hpp"
#include "core/error.hpp"
#include "core/prefault.hpp"
#include "hierarchy/bounding_sphere.hpp"
#include "hierarchy/cluster_dag.hpp"
#include "hierarchy/hlod.hpp"
#include "hierarchy/progressive_steps.hpp"
#include "io/import.hpp"
#include "package/node_codec.hpp"
#include "package/progressive_prefix.hpp"
#include "package/records.hpp"
#include "package/writer.hpp"
#include "schedule/screen_error.hpp"
#include "timing.hpp"

namespace lodstream::cli {
namespace {

using namespace package;

// Meshes of at most this many triangles become progressive meshes (hierarchy/progressive_steps.hpp), larger
// ones cluster DAGs. Why 2048: as a DAG such a mesh is 16 clusters, 3-4 levels and about 2 x 2048 stored
// triangles (1.67 x since the group ratio is 0.4; the figures below were measured at 0.5), ~20 KB encoded:
// less than one 40 KB page, so the DAG's per-cluster selection buys nothing (a page is what travels), while a
// progressive mesh stores each triangle once and streams it in about 3 steps (base, then doubling). Measured
// (bench stream gen:fly, 10 Mbit/s 80 ms, push time to benefit 0.95): motorBike 2.10 s all-DAG, 2.03 s at
// 2048, 2.20 s at 8192; city 2.20 s all-DAG, 2.30 s at 2048, 2.37 s at 8192 (sse-pull 4.37 -> 3.97 s at
// both); larger N loses view-dependent refinement on objects that fill the screen, and steps that double
// overshoot tau by up to 2x triangles.
constexpr uint32_t kDefaultPmMaxTriangles = 2048;
// A step's vertices must fit one codec node (65536); a mesh of T triangles has at most 3T vertices.
constexpr uint32_t kMaxPmTriangles = 21845;

struct BakeArgs {
  std::vector<std::string> models;
  std::string output;
  bool json = false, hlod = true;
  uint32_t normal_bits = 9, coarse_normal_bits = 7;
  int max_grid_bits = 20;
  uint32_t codec = default_node_codec().id();
  uint32_t pm_max_triangles = kDefaultPmMaxTriangles;
  // The DAG's shape (--group-ratio, --group-clusters, --cluster-triangles): dag_options() checks it and
  // fills the vertex limit.
  hierarchy::DagOptions dag;
  uint32_t cluster_triangles = uint32_t(hierarchy::DagOptions{}.max_cluster_triangles);
};

// Limits of the DAG's shape options. A group's target must stay under DagOptions::stuck_ratio (0.85) with
// the 10 % slack a group may miss it by and still count as reaching it. A cluster's vertices must fit
// cluster_dag.cpp's per-cluster edge table (255) and its triangles meshoptimizer's meshlet limit (512). A
// group of one cluster has no neighbour to simplify across its locked border; 31 clusters is the most a
// record holds (NodeCodec::max_record_clusters), so a group's input clusters stay one record.
constexpr double kMinGroupRatio = 0.1, kMaxGroupRatio = 0.75;
constexpr uint32_t kMinClusterTriangles = 16, kMaxClusterTriangles = 512, kMaxClusterVertices = 255;
constexpr size_t kMinGroupClusters = 2, kMaxGroupClusters = 31;

// The DAG options of --group-ratio, --group-clusters and --cluster-triangles; throws lodstream::Error (one
// line naming the option) outside their ranges. A cluster of N triangles may have N vertices (what 128 / 128
// gave), at most 255: an open patch of N triangles has about N / 2 vertices plus half its border, so the
// vertex limit binds only on seams or past ~400 triangles.
hierarchy::DagOptions dag_options(const BakeArgs& args) {
  hierarchy::DagOptions o = args.dag;
  if (!(o.group_ratio >= kMinGroupRatio && o.group_ratio <= kMaxGroupRatio))
    throw Error("--group-ratio: must be in 0.1..0.75");
  if (o.group_clusters < kMinGroupClusters || o.group_clusters > kMaxGroupClusters)
    throw Error("--group-clusters: must be in 2..31");
  if (args.cluster_triangles < kMinClusterTriangles || args.cluster_triangles > kMaxClusterTriangles ||
      args.cluster_triangles % 4 != 0)
    throw Error("--cluster-triangles: must be a multiple of 4 in 16..512");
  o.max_cluster_triangles = args.cluster_triangles;
  o.max_cluster_vertices = std::min(args.cluster_triangles, kMaxClusterVertices);
  return o;
}

uint64_t peak_rss_bytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  return 0;
}

uint32_t position_shift(float error, const PositionGrid& grid) {
  if (!(error > 0.0f) || std::isinf(error)) return 0;
  const double k = std::floor(std::log2(double(error) / (16.0 * double(grid.step))));
  return uint32_t(std::clamp(k, 0.0, 16.0));
}

// q(e) of the header comment: the extra error of a node stored with the shift for error e.
float quantization_error(float error, const PositionGrid& grid) {
  const uint32_t k = position_shift(error, grid);
  return k == 0 ? 0.0f : float(std::sqrt(3.0) * 0.5 * std::ldexp(double(grid.step), int(k)));
}

float stored_error(float error, const PositionGrid& grid) {
  const float q = quantization_error(error, grid);
  return q == 0.0f ? error : std::nextafter(error + q, INFINITY);
}
Sphere stored_sphere(const Sphere& s, float error, const PositionGrid& grid) {
  const float q = std::isinf(error) ? 0.0f : quantization_error(error, grid);
  return q == 0.0f ? s : Sphere{s.center, std::nextafter(s.radius + q, INFINITY)};
}

// Normal precision of a DAG cluster: --normal-bits at level 0 (error 0), at most --coarse-normal-bits above.
// A coarse cluster's triangles stand for finer ones and their normals carry that approximation. Measured
// (codec 3; bake, then render --pixel-error 1 at 1280x720 against the full model from eyes (0.5,0.2,0.6),
// (1.5,0.5,1.5), (4,1.5,4) looking at the origin; PSNR near / mid / far in dB), coarse bits 10 / 8 / 7 / 6:
// elephant_1m 7,663,893 / 7,279,505 (-5.0 %) / 7,023,282 / 6,808,963 B, PSNR 49.11 / 61.63 / 61.84, 49.02 /
// 61.43 / 61.80, 48.83 / 60.97 / 61.71, 48.18 / 59.82 / 61.47; refined_elephant 593,823 / 569,408 (-4.1 %) /
// 552,395 / 536,052 B, PSNR 46.12 / 53.73 / 59.07, 46.09 / 53.70 / 59.07, 46.03 / 53.67 / 59.08, 45.81 /
// 53.40 / 58.87. 8 bits costs at most 0.2 dB; 7 and 6 lose 0.3-1.8 dB.
// Level 0 (--normal-bits, default 9: at most ~0.35 degrees off; progressive meshes too), measured the same
// way (lead; elephant_1m with up +y, motorBike with examples/cameras front / side / above), 10 / 9 / 8 bits:
// elephant_1m 6,749,830 / 6,542,992 (-3.1 %) / 6,356,482 B, PSNR near / mid / far 47.45 / 54.65
// / 64.91, 47.45 / 54.65 / 64.91, 47.44 / 54.65 (far not measured); motorBike 2,367,040 / 2,323,447 (-1.8 %)
// / 2,281,899 B, PSNR 47.97 / 45.40 / 47.43, 47.96 / 45.40 / 47.42, 47.96 / 45.39 / 47.41. Both cost under
// 0.02 dB; 9 keeps a margin for close-up views and specular shading, which these renders do not test.
// (Recomputing the normals from the snapped positions, which the codec predicts exactly, saved 5.4 % but cost
// 0.2 dB near and 3.3 dB far: quantized positions tilt face normals by more than 8-bit octahedral rounding
// does.) These figures are of format 5's global octahedral code; format 6 codes a normal in the frame of its
// prediction at the same RMS angular error for the same bits (predicted_normals.hpp).
// A cluster whose position shift is at least 2 (error >= 64 finest steps) stored one normal bit less
// (format 7, same renders; PSNR near / mid / far, motorBike front / side / above), against 8 bits at every
// coarse level, one bit less from shift 1 / 2 / 3 / everywhere: elephant_1m 3,939,809 -> 3,920,917 /
// 3,929,606 (-0.26 %) / 3,933,993 / 3,779,090 B, PSNR 48.599 / 61.097 / 61.434 -> far 61.384 / 61.430 /
// 61.434 / 48.480, 60.897, 61.362 (near and mid unchanged but for the last); refined_elephant 335,287 ->
// 333,317 / 333,606 (-0.50 %) B, PSNR at most +0.014 dB; motorBike 1,662,656 -> 1,644,160 / 1,647,075
// (-0.94 %) B, PSNR 47.786 / 46.000 / 48.067 -> 47.780 / 45.995 / 48.057 (shift 1), 47.785 / 45.994 / 48.064
// (shift 2); the same triangles in every view.
// Format 14 (helper sizepos, issue 4's package goal): --coarse-normal-bits 7 by default, and one bit less
// (6) from error >= kFewerNormalBitsSteps = 16 finest steps (2^-10 of the diagonal on a 14-bit grid: the
// page groups of level 2 and up; level 1's are 5-9 steps at their finest cluster, which sets the page
// group's bits). Errors, spheres and so the triangles drawn are unchanged; the cost is 0.0-0.3 dB of PSNR.
// Measured (bake, render at 1 px against the full model, the usual cameras; PSNR near / mid / far,
// motorBike above / front / side) against format 13's 8 bits and one less from 64 steps, then 7 bits and
// one less from 64 steps / from 16: refined_elephant 234,946 -> 226,444 / 225,434 B (-4.05 %), PSNR 47.600 /
// 50.943 / 56.511 -> 47.577 / 50.791 / 56.372 / 47.577 / 50.798 / 56.337; elephant_1m 2,642,733 ->
// 2,542,582 / 2,535,327 (-4.06 %), PSNR 47.610 / 54.903 / 59.838 -> 47.402 / 54.681 / 59.699 / 47.402 /
// 54.671 / 59.635; then (bench/compare-binaries) bunny 225,833 -> 214,701 B (-4.9 %), PSNR 54.908 / 50.290 /
// 53.605 -> 54.908 / 50.290 / 53.328; horse 291,669 -> 280,746 (-3.7 %), 57.892 / 59.377 / 69.820 -> 57.612
// / 59.087 / 69.528; motorBike 1,333,793 -> 1,305,234 (-2.1 %), 47.853 / 47.670 / 45.619 -> 47.801 / 47.588
// / 45.546. Keeping 8 bits at level 1 (one less from 16 steps, two from 64) saved only 1.5 % / 0.7 %: level
// 1 holds most coarse normals. The other lever, the positions'
// shift (position_shift's divisor 16 -> 8 / 4 / 2, normals as format 13), saved 0.03 / 0.75 / 2.0 % on
// refined_elephant (a page group's shift is its finest cluster's), and clients drew more triangles at a lower
// PSNR: divisor 4 near / mid / far 69,692 / 35,012 / 18,138 triangles (+3.9 / +4.4 / 0 %), 47.718 / 50.614 /
// 56.000 dB; divisor 2 (with its coupled normal rule) 75,618 / 37,640 / 18,614, 47.888 / 51.158 / 55.899.
constexpr double kFewerNormalBitsSteps = 16.0;

uint32_t cluster_normal_bits(float error, const PositionGrid& grid, const BakeArgs& args) {
  if (!(error > 0.0f)) return args.normal_bits;
  const uint32_t coarse = std::min(args.normal_bits, args.coarse_normal_bits);
  return double(error) >= kFewerNormalBitsSteps * double(grid.step) && coarse > 4 ? coarse - 1 : coarse;
}

// How a DAG cluster is stored: (position shift, normal bits).
std::pair<uint32_t, uint32_t> precision(const hierarchy::DagCluster& c, const PositionGrid& grid,
                                        const BakeArgs& args) {
  return {position_shift(c.error, grid), cluster_normal_bits(c.error, grid, args)};
}

// How a page group's DAG clusters (a group's input clusters, or a DAG's roots) are stored, in every record
// of the group: the smallest position shift and the largest normal bits of its clusters. A free vertex is
// shared only by clusters of one producing group and one consuming group (the header comment), that is only
// inside one page group, so it decodes alike wherever it is stored, even when the page group is cut into
// several records (more than NodeCodec::max_record_clusters() clusters: a stalled DAG's roots). Precision
// per record instead cracked the city: 32 roots of mixed levels cut 31 + 1, a free vertex shared by two
// siblings (roots of one group) decoded at shift 10 in one record and 13 in the other. Costs O(clusters).
std::pair<uint32_t, uint32_t> page_group_precision(const hierarchy::ClusterDag& dag,
                                                   std::span<const uint32_t> clusters,
                                                   const PositionGrid& grid, const BakeArgs& args) {
  std::pair<uint32_t, uint32_t> stored = precision(dag.clusters[clusters[0]], grid, args);
  for (uint32_t c : clusters) {
    const auto [shift, normal_bits] = precision(dag.clusters[c], grid, args);
    stored = {std::min(stored.first, shift), std::max(stored.second, normal_bits)};
  }
  return stored;
}

// A record (package/records.hpp): DAG clusters of one page group welded into one mesh on their identical
// vertices (same position and attributes: seams stay split), each cluster's triangles a consecutive range,
// stored as one node with one vertex pool, free vertices at the page group's precision `stored`
// (page_group_precision), every vertex locked in any of them exactly. A vertex thus decodes alike in every
// record of its page group and locked vertices everywhere, so cuts stay crack-free. Against one record per
// precision this rounds a coarse cluster's free vertices finer than its error allows and stores coarse
// normals at the page group's largest bits.
std::vector<uint8_t> encode_record(const NodeCodec& codec, const hierarchy::ClusterDag& dag,
                                   std::span<const uint32_t> clusters, std::pair<uint32_t, uint32_t> stored,
                                   const PositionGrid& grid) {
  std::vector<const Mesh*> meshes;
  std::vector<std::span<const uint8_t>> locked;
  NodeGeometry geometry;
  std::tie(geometry.position_shift, geometry.normal_bits) = stored;
  for (uint32_t c : clusters) {
    meshes.push_back(&dag.clusters[c].mesh);
    locked.push_back(dag.clusters[c].locked);
  }
  const RecordMesh record = weld_record(meshes, locked);
  geometry.mesh = &record.mesh;
  if (geometry.position_shift > 0) geometry.locked = record.locked;
  if (clusters.size() > 1) geometry.cluster_triangles = record.cluster_triangles;
  return codec.encode(geometry, grid);
}

// The records of a page group of `clusters` DAG clusters (in page order): runs of `max` consecutive
// clusters, the last one shorter; returns the runs' lengths.
std::vector<uint32_t> record_runs(size_t clusters, uint32_t max) {
  std::vector<uint32_t> runs;
  for (size_t i = 0; i < clusters; i += max) runs.push_back(uint32_t(std::min<size_t>(max, clusters - i)));
  return runs;
}

// Page groups of several DAG groups: the input clusters of consecutive groups of one level (ids g, g + 1,
// ...: a level's groups are numbered together, METIS's parts in order, mostly neighbours) whose inputs become
// final together (one DagOptions::inputs_final call) form one page group, and so one record, while they hold
// at most `max_clusters` clusters together. The DAG, each cluster's error and sphere and so every cut stay
// the same; what changes is the record: a vertex on the border between two of those groups (locked: held by
// clusters of both) is stored and predicted once instead of once in each group's record, and a vertex whose
// fan the border cut is closed in the joined record (its normal derived, package/derived_normals.hpp). The
// page group's precision is its clusters' finest (page_group_precision), so a free vertex is still stored
// at one shift. Measured (bake, render at 1 px against the full model from the usual three cameras; records
// of one group each -> joined up to the 31 clusters a record holds): refined_elephant 288,725 -> 271,148 B
// (-6.1 %), the same triangles drawn, PSNR 47.629 / 51.025 / 56.261 -> 47.628 / 51.023 / 56.549 dB;
// elephant_1m 3,127,899 -> 2,972,234 (-5.0 %), bunny -4.7 %, horse -4.2 %, motorBike -3.6 % (PSNR within
// -0.06..+0.06 dB, the same triangles); elephant_5m 2.126 -> 1.979 B per input triangle (with derived
// normals). A client that needs one group's clusters decodes the whole record (up to about 4 groups' inputs,
// a few KB; pages hold tens of records). `groups` in any
// order; sets joins[g] for each group g joined with g + 1 (joins grows to the DAG's groups) and returns the
// page groups' clusters, each a run of joined groups' children in group order. Cost: O(groups log groups +
// their children).
std::vector<std::vector<uint32_t>> join_groups(const hierarchy::ClusterDag& dag,
                                               std::span<const uint32_t> groups, uint32_t max_clusters,
                                               std::vector<uint8_t>& joins) {
  std::vector<uint32_t> sorted(groups.begin(), groups.end());
  std::sort(sorted.begin(), sorted.end());
  joins.resize(dag.groups.size(), 0);
  std::vector<std::vector<uint32_t>> page_groups;
  for (size_t i = 0; i < sorted.size(); ++i) {
    const hierarchy::DagGroup& g = dag.groups[sorted[i]];
    const bool join = i > 0 && sorted[i] == sorted[i - 1] + 1 && g.level == dag.groups[sorted[i - 1]].level &&
                      page_groups.back().size() + g.children.size() <= max_clusters;
    if (join)
      joins[sorted[i - 1]] = 1;
    else
      page_groups.emplace_back();
    page_groups.back().insert(page_groups.back().end(), g.children.begin(), g.children.end());
  }
  return page_groups;
}

Sphere float_sphere(const schedule::WorldSphere& w) {
  return {glm::vec3(w.center), std::nextafter(float(w.radius), INFINITY)};
}

// A representation's coarsest geometry as the HLOD merges it: its roots' meshes, stored errors and spheres,
// and their vertices' carried radii (DagCluster::vertex_error; null or empty: `error` at every vertex).
struct RootPiece {
  const Mesh* mesh;
  float error;
  Sphere sphere;
  const std::vector<float>* radii = nullptr;
};

// The HLOD's input: each object's roots (errors and spheres as stored) under its transform, its bounds'
// sphere included (what culling tests). Objects of an empty mesh are left out; `ids` maps back.
std::vector<hierarchy::HlodObject> hlod_inputs(const Scene& scene,
                                               const std::vector<std::vector<RootPiece>>& roots,
                                               const std::vector<Bounds>& bounds,
                                               std::vector<uint32_t>& ids) {
  for (uint32_t o = 0; o < scene.objects.size(); ++o)
    if (!bounds[scene.objects[o].mesh].empty()) ids.push_back(o);
  std::vector<hierarchy::HlodObject> out(ids.size());
  tbb::parallel_for(size_t(0), ids.size(), [&](size_t i) {
    const Object& object = scene.objects[ids[i]];
    const Bounds& b = bounds[object.mesh];
    const glm::mat4& t = object.transform;
    const double scale = schedule::max_scale(t);
    const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(t)));
    hierarchy::HlodObject& h = out[i];
    for (int corner = 0; corner < 8; ++corner) {
      const glm::vec3 p(corner & 1 ? b.max.x : b.min.x, corner & 2 ? b.max.y : b.min.y,
                        corner & 4 ? b.max.z : b.min.z);
      h.bounds.add(glm::vec3(t * glm::vec4(p, 1.0f)));
    }
    std::vector<Sphere> spheres{
        float_sphere(schedule::to_world({b.center(), 0.5f * b.diagonal()}, t, scale))};
    double error = 0.0;
    for (const RootPiece& r : roots[object.mesh]) {
      error = std::max(error, double(r.error) * scale);
      spheres.push_back(float_sphere(schedule::to_world(r.sphere, t, scale)));
      const uint32_t base = uint32_t(h.coarse.positions.size());
      for (const glm::vec3& p : r.mesh->positions)
        h.coarse.positions.push_back(glm::vec3(t * glm::vec4(p, 1.0f)));
      const bool carried = r.radii && r.radii->size() == r.mesh->positions.size();
      for (size_t v = 0; v < r.mesh->positions.size(); ++v)
        h.coarse_error.push_back(
            std::nextafter(float(double(carried ? (*r.radii)[v] : r.error) * scale), INFINITY));
      for (const glm::vec3& n : r.mesh->normals)
        h.coarse.normals.push_back(glm::normalize(normal_matrix * n));
      for (uint32_t k : r.mesh->indices) h.coarse.indices.push_back(base + k);
      h.coarse.material = r.mesh->material;
    }
    h.error = std::nextafter(float(error), INFINITY);
    h.sphere = hierarchy::sphere_of_spheres(spheres);
  });
  return out;
}

// The scene of all models: materials, meshes and objects concatenated.
Scene import_all(const std::vector<std::string>& models) {
  Scene all;
  for (const std::string& model : models) {
    Scene s = import_model(model);
    const uint32_t materials = uint32_t(all.materials.size()), meshes = uint32_t(all.meshes.size());
    for (Material& m : s.materials) all.materials.push_back(std::move(m));
    for (Mesh& m : s.meshes) {
      m.material += materials;
      all.meshes.push_back(std::move(m));
    }
    for (Object& o : s.objects) {
      o.mesh += meshes;
      all.objects.push_back(std::move(o));
    }
  }
  return all;
}

int run_bake(const BakeArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // Wall and CPU (all threads) seconds per phase, for --json: a phase whose CPU is near its wall time ran on
  // one core.
  nlohmann::json phases;
  double phase_wall = 0.0, phase_cpu = 0.0;
  auto end_phase = [&](const char* name) {
    const double wall = elapsed(), cpu = process_cpu_s();
    phases[name] = {{"wall_s", wall - phase_wall}, {"cpu_s", cpu - phase_cpu}};
    phase_wall = wall, phase_cpu = cpu;
  };
  phase_cpu = process_cpu_s();
  if (args.normal_bits < 4 || args.normal_bits > 16) throw Error("--normal-bits: must be in 4..16");
  if (args.coarse_normal_bits < 4 || args.coarse_normal_bits > 16)
    throw Error("--coarse-normal-bits: must be in 4..16");
  if (args.max_grid_bits < 14 || args.max_grid_bits > 20) throw Error("--max-grid-bits: must be in 14..20");
  try {
    package::node_codec(args.codec);  // the registry of codec ids
  } catch (const Error& e) {
    throw Error(std::string("--codec: ") + e.what() + " (1, 2 or 3)");
  }
  if (args.pm_max_triangles > kMaxPmTriangles)
    throw Error("--pm-max-triangles: must be in 0.." + std::to_string(kMaxPmTriangles));
  const hierarchy::DagOptions dag_shape = dag_options(args);
  Scene scene = import_all(args.models);
  end_phase("import");
  const uint64_t input_triangles = scene.triangle_count();
  const size_t unique_triangles = scene.unique_triangle_count();
  std::fprintf(stderr, "bake: %zu objects, %zu meshes, %llu triangles imported in %.2f s\n",
               scene.objects.size(), scene.meshes.size(), (unsigned long long)input_triangles, elapsed());

  // One DAG or progressive mesh per stored mesh; meshes in parallel (DAGs also parallel inside).
  std::vector<hierarchy::ClusterDag> dags(scene.meshes.size());
  std::vector<hierarchy::ProgressiveSteps> pms(scene.meshes.size());  // steps empty: a DAG
  std::vector<Bounds> bounds(scene.meshes.size());
  std::vector<PositionGrid> grids(scene.meshes.size());
  const NodeCodec& codec = node_codec(args.codec);
  // Records encoded during the build, by mesh and by their first cluster (DagOptions::inputs_final).
  std::vector<std::vector<std::vector<uint8_t>>> early(scene.meshes.size());
  // By mesh and group: its page group continues with the next group's input clusters (join_groups).
  std::vector<std::vector<uint8_t>> joins(scene.meshes.size());
  std::atomic<size_t> done_triangles{0};
  std::mutex progress_mutex;
  int shown_percent = -1;  // the bar is redrawn when the percentage changes (not per cluster batch)
  auto report = [&](size_t add) {
    const size_t done = done_triangles += add;
    std::lock_guard lock(progress_mutex);
    const int percent = int(100.0 * double(done) / double(std::max<size_t>(1, unique_triangles)));
    if (percent == shown_percent) return;
    shown_percent = percent;
    std::fprintf(stderr, "\rbake: hierarchy [%-40s] %3d%% %.1f s",
                 std::string(size_t(percent * 40 / 100), '#').c_str(), percent, elapsed());
    std::fflush(stderr);
  };
  tbb::parallel_for(size_t(0), scene.meshes.size(), [&](size_t m) {
    bounds[m] = scene.meshes[m].bounds();
    grids[m] = PositionGrid::separating(scene.meshes[m], 14, args.max_grid_bits);
    grids[m].snap(scene.meshes[m]);
    const size_t triangles = scene.meshes[m].triangle_count();
    if (triangles > 0 && triangles <= args.pm_max_triangles) {
      pms[m] = hierarchy::build_progressive_steps(scene.meshes[m]);
      if (!pms[m].steps.empty()) {  // else (nothing left after welding): a DAG, as before
        report(triangles);
        scene.meshes[m] = Mesh{};
        return;
      }
    }
    hierarchy::DagOptions options = dag_shape;
    size_t reported = 0;
    options.progress = [&](uint32_t, size_t active) {
      // Each level removes about 1 - group_ratio of what is left: count the removed triangles as done.
      const size_t done_here = triangles - std::min(triangles, active);
      if (done_here > reported) report(done_here - reported), reported = done_here;
    };
    options.inputs_final = [&, m](const hierarchy::ClusterDag& dag, std::span<const uint32_t> groups) {
      std::vector<std::vector<uint8_t>>& out = early[m];
      out.resize(dag.clusters.size());
      const std::vector<std::vector<uint32_t>> page_groups =
          join_groups(dag, groups, codec.max_record_clusters(), joins[m]);
      tbb::parallel_for(size_t(0), page_groups.size(), [&](size_t i) {
        const std::vector<uint32_t>& children = page_groups[i];
        const auto stored = page_group_precision(dag, children, grids[m], args);
        size_t first = 0;
        for (uint32_t count : record_runs(children.size(), codec.max_record_clusters())) {
          std::vector<uint8_t>& bytes = out[children[first]];
          bytes = encode_record(codec, dag, std::span(children).subspan(first, count), stored, grids[m]);
          bytes.shrink_to_fit();  // kept until the pages are written: no growth slack
          first += count;
        }
      });
    };
    dags[m] = hierarchy::build_cluster_dag(std::move(scene.meshes[m]), options);  // the DAG holds it now
    report(triangles - reported);
    scene.meshes[m] = Mesh{};
  });
  std::fprintf(stderr, "\n");

  end_phase("hierarchy");

  // HLOD over the objects (none for a single object).
  const double hlod_start = elapsed();
  hierarchy::Hlod hlod;
  std::vector<uint32_t> hlod_objects;  // HLOD object index -> scene object
  Bounds world;
  if (args.hlod && scene.objects.size() > 1) {
    std::vector<std::vector<RootPiece>> roots(dags.size());
    for (size_t m = 0; m < dags.size(); ++m) {
      if (!pms[m].steps.empty()) {
        const float e = pms[m].steps[0].error;
        roots[m].push_back({&pms[m].base, e, pms[m].sphere});
      }
      for (uint32_t r : dags[m].roots) {
        const hierarchy::DagCluster& c = dags[m].clusters[r];
        roots[m].push_back({&c.mesh, stored_error(c.error, grids[m]),
                            stored_sphere(c.sphere, c.error, grids[m]), &c.vertex_error});
      }
    }
    const std::vector<hierarchy::HlodObject> inputs = hlod_inputs(scene, roots, bounds, hlod_objects);
    for (const hierarchy::HlodObject& h : inputs) world.add(h.bounds.min), world.add(h.bounds.max);
    hierarchy::HlodOptions options;
    options.position_tolerance = float(std::sqrt(3.0) * 0.5 * PositionGrid::for_bounds(world, 14).step);
    for (const Material& m : scene.materials) options.material_colors.push_back(m.base_color);
    options.mixed_material = uint32_t(scene.materials.size());
    hlod = hierarchy::build_hlod(inputs, options);
    bool mixed = false;
    for (hierarchy::HlodNode& n : hlod.nodes) {
      for (uint32_t& o : n.objects) o = hlod_objects[o];
      mixed = mixed || n.mesh.material == options.mixed_material;
    }
    if (mixed) {  // proxies of several materials: white, untextured, their vertex colours carry the look
      Material white;
      white.name = "hlod-vertex-colors";
      white.base_color = glm::vec4(1.0f);
      scene.materials.push_back(std::move(white));
    }
  }
  const double hlod_time = elapsed() - hlod_start;
  end_phase("hlod");

  // Representations, and the node order: HLOD top levels and roots, then the other HLOD nodes, then each
  // group's input clusters, coarse levels first.
  PackageScene ps;
  ps.input_triangles = input_triangles;
  struct Ref {
    uint32_t mesh, cluster;  // mesh == kNone: HLOD node `cluster`; a progressive mesh's: step `cluster`
  };
  std::vector<Ref> order;
  std::vector<std::vector<uint32_t>> node_id(dags.size());
  std::vector<uint32_t> hlod_id(hlod.nodes.size(), kNone);
  std::vector<size_t> page_group_ends;
  // The HLOD's nodes of depth <= 2 (breadth-first ids: a prefix) go into the root index.
  size_t hlod_top = 0;
  {
    std::vector<uint32_t> depth(hlod.nodes.size(), 0);
    for (uint32_t id = 0; id < hlod.nodes.size(); ++id) {
      if (hlod.nodes[id].parent != hierarchy::kNoHlodNode) depth[id] = depth[hlod.nodes[id].parent] + 1;
      if (depth[id] <= 2) hlod_top = id + 1;
    }
  }
  for (uint32_t id = 0; id < hlod_top; ++id) {
    hlod_id[id] = uint32_t(order.size());
    order.push_back({kNone, id});
  }
  if (hlod_top > 0) page_group_ends.push_back(order.size());
  uint32_t levels = hlod.levels;
  size_t abandoned = 0, partial = 0, positions_only = 0, dropped_components = 0, stalled = 0;
  for (uint32_t m = 0; m < dags.size(); ++m) {
    const hierarchy::ClusterDag& dag = dags[m];
    if (!pms[m].steps.empty()) {  // a progressive mesh: step 0 is its root
      node_id[m].assign(pms[m].steps.size(), kNone);
      Representation rep;
      rep.kind = RepresentationKind::progressive_mesh;
      rep.name = "mesh" + std::to_string(m);
      rep.bounds = bounds[m];
      rep.grid = grids[m];
      rep.levels = 1;  // DESIGN.md: a progressive mesh counts as 1
      node_id[m][0] = uint32_t(order.size());
      rep.roots = {uint32_t(order.size())};
      order.push_back({m, 0});
      page_group_ends.push_back(order.size());
      ps.representations.push_back(std::move(rep));
      levels = std::max(levels, 1u);
      continue;
    }
    node_id[m].assign(dag.clusters.size(), kNone);
    Representation rep;
    rep.kind = RepresentationKind::cluster_dag;
    rep.name = "mesh" + std::to_string(m);
    rep.bounds = bounds[m];
    rep.grid = grids[m];
    rep.levels = std::max(1u, dag.levels);
    for (uint32_t r : dag.roots) {
      node_id[m][r] = uint32_t(order.size());
      rep.roots.push_back(uint32_t(order.size()));
      order.push_back({m, r});
    }
    page_group_ends.push_back(order.size());
    ps.representations.push_back(std::move(rep));
    levels = std::max(levels, dag.levels);
    abandoned += dag.abandoned_groups;
    stalled += dag.stalled;
    for (const hierarchy::DagGroup& g : dag.groups) {
      partial += g.outcome == hierarchy::GroupOutcome::partial;
      positions_only += g.outcome == hierarchy::GroupOutcome::positions_only;
      dropped_components += g.outcome == hierarchy::GroupOutcome::components_dropped;
    }
  }
  const uint32_t hlod_representation = uint32_t(ps.representations.size());
  if (!hlod.nodes.empty()) {
    Representation rep;
    rep.kind = RepresentationKind::hlod;
    rep.name = "hlod";
    rep.bounds = world;
    rep.grid = PositionGrid::for_bounds(world, 14);
    rep.levels = hlod.levels;
    rep.roots = {hlod_id[hlod.root]};
    ps.representations.push_back(std::move(rep));
  }
  const uint32_t root_nodes = uint32_t(order.size());
  for (uint32_t id = uint32_t(hlod_top); id < hlod.nodes.size(); ++id) {
    hlod_id[id] = uint32_t(order.size());
    order.push_back({kNone, id});
    if (id + 1 == hlod.nodes.size() || hlod.nodes[id + 1].parent != hlod.nodes[id].parent)
      page_group_ends.push_back(order.size());
  }
  // Progressive meshes: steps 1.. of each, one page group per step, in step order (what a client needs next
  // for an object is its next step).
  for (uint32_t m = 0; m < pms.size(); ++m)
    for (uint32_t k = 1; k < pms[m].steps.size(); ++k) {
      node_id[m][k] = uint32_t(order.size());
      order.push_back({m, k});
      page_group_ends.push_back(order.size());
    }
  struct GroupRef {
    uint32_t level, mesh, group;
  };
  std::vector<GroupRef> groups;
  for (uint32_t m = 0; m < dags.size(); ++m)
    for (uint32_t g = 0; g < dags[m].groups.size(); ++g) groups.push_back({dags[m].groups[g].level, m, g});
  std::stable_sort(groups.begin(), groups.end(),
                   [](const GroupRef& a, const GroupRef& b) { return a.level > b.level; });
  for (const GroupRef& gr : groups) {
    for (uint32_t c : dags[gr.mesh].groups[gr.group].children) {
      node_id[gr.mesh][c] = uint32_t(order.size());
      order.push_back({gr.mesh, c});
    }
    const std::vector<uint8_t>& joined = joins[gr.mesh];
    if (!(gr.group < joined.size() && joined[gr.group])) page_group_ends.push_back(order.size());
  }
  for (const Object& o : scene.objects) ps.objects.push_back({o.name, o.transform, o.mesh});

  // Records.
  std::vector<NodeRecord> records;
  resize_prefaulted(records, order.size());  // core/prefault.hpp: constructed on this thread
  tbb::parallel_for(size_t(0), order.size(), [&](size_t id) {
    NodeRecord& n = records[id];
    if (order[id].mesh == kNone) {
      const hierarchy::HlodNode& h = hlod.nodes[order[id].cluster];
      n.kind = NodeKind::hlod_proxy;
      n.representation = hlod_representation;
      n.material = h.mesh.material;
      n.level = h.level;
      n.triangles = uint32_t(h.mesh.triangle_count());
      n.error = h.error;
      n.sphere = h.sphere;
      if (h.parent != hierarchy::kNoHlodNode) {
        n.parent_error = hlod.nodes[h.parent].error;
        n.parent_sphere = hlod.nodes[h.parent].sphere;
        n.parents = {hlod_id[h.parent]};
      }
      for (uint32_t c : h.children) n.children.push_back(hlod_id[c]);
      n.objects = h.objects;
      return;
    }
    if (!pms[order[id].mesh].steps.empty()) {  // a progressive step: the chain step k-1 -> k -> k+1
      const hierarchy::ProgressiveSteps& pm = pms[order[id].mesh];
      const uint32_t k = order[id].cluster, steps = uint32_t(pm.steps.size());
      const hierarchy::ProgressiveStep& s = pm.steps[k];
      const auto& ids = node_id[order[id].mesh];
      n.kind = NodeKind::progressive_step;
      n.representation = order[id].mesh;
      n.material = s.mesh.material;
      n.level = steps - 1 - k;  // 0 = the finest step
      n.triangles = uint32_t(s.mesh.triangle_count());
      n.error = s.error;  // the prefix's bound; the finest grid's rounding is not counted (as DAG level 0)
      n.sphere = n.parent_sphere = pm.sphere;
      if (k > 0) n.parent_error = pm.steps[k - 1].error, n.parents = {ids[k - 1]};
      if (k + 1 < steps) n.children = {ids[k + 1]};
      return;
    }
    const hierarchy::ClusterDag& dag = dags[order[id].mesh];
    const hierarchy::DagCluster& c = dag.clusters[order[id].cluster];
    const PositionGrid& grid = ps.representations[order[id].mesh].grid;
    const auto& ids = node_id[order[id].mesh];
    n.kind = NodeKind::cluster;
    n.representation = order[id].mesh;
    n.material = c.mesh.material;
    n.level = c.level;
    n.triangles = uint32_t(c.mesh.triangle_count());
    n.error = stored_error(c.error, grid);
    n.sphere = stored_sphere(c.sphere, c.error, grid);
    n.parent_error = stored_error(c.parent_error, grid);
    n.parent_sphere = stored_sphere(c.parent_sphere, c.parent_error, grid);
    if (c.group != hierarchy::kNoGroup)
      for (uint32_t k : dag.groups[c.group].children) n.children.push_back(ids[k]);
    if (c.parent_group != hierarchy::kNoGroup) {
      for (uint32_t k : dag.groups[c.parent_group].clusters) n.parents.push_back(ids[k]);
      std::sort(n.parents.begin(), n.parents.end());  // as the index derives them (index.hpp)
    }
  });

  // Encode, in parallel a batch of page groups at a time, and write (serial). Records: within a page group,
  // consecutive DAG clusters (a group's input clusters, or a DAG's roots) are one record of at most
  // codec.max_record_clusters() clusters (encode_record); every other node is stored alone.
  WriterOptions writer_options;
  writer_options.codec = args.codec;
  PackageWriter writer(args.output, writer_options);
  NodeSizeBreakdown breakdown;
  auto is_cluster = [&](size_t id) { return order[id].mesh != kNone && pms[order[id].mesh].steps.empty(); };
  struct Record {
    size_t first, count;                   // node ids [first, first + count)
    std::pair<uint32_t, uint32_t> stored;  // a DAG record's page_group_precision
  };
  std::vector<Record> batch;
  std::vector<std::vector<uint8_t>> encoded;
  size_t first = 0;
  for (size_t g = 0; g < page_group_ends.size();) {
    batch.clear();
    for (size_t nodes = 0; g < page_group_ends.size() && (batch.empty() || nodes < 4096); ++g) {
      if (is_cluster(first)) {  // one DAG's clusters (a group's inputs, or its roots)
        const uint32_t m = order[first].mesh;
        std::vector<uint32_t> clusters;
        for (size_t id = first; id < page_group_ends[g]; ++id) clusters.push_back(order[id].cluster);
        const auto stored = page_group_precision(dags[m], clusters, grids[m], args);
        size_t id = first;
        for (uint32_t count : record_runs(clusters.size(), codec.max_record_clusters()))
          batch.push_back({id, count, stored}), id += count;
      } else {
        for (size_t id = first; id < page_group_ends[g]; ++id) batch.push_back({id, 1, {}});
      }
      nodes += page_group_ends[g] - first;
      first = page_group_ends[g];
      batch.push_back({first, 0, {}});  // the page group's end
    }
    encoded.assign(batch.size(), {});
    tbb::parallel_for(size_t(0), batch.size(), [&](size_t r) {
      const size_t id = batch[r].first;
      if (batch[r].count == 0) return;
      NodeGeometry geometry;
      geometry.normal_bits = args.normal_bits;
      if (order[id].mesh == kNone) {  // an HLOD proxy: finest grid of the HLOD representation
        geometry.mesh = &hlod.nodes[order[id].cluster].mesh;
        encoded[r] = codec.encode(geometry, ps.representations[hlod_representation].grid);
        return;
      }
      if (!pms[order[id].mesh].steps.empty()) {  // a progressive step: finest grid, order kept
        const hierarchy::ProgressiveSteps& pm = pms[order[id].mesh];
        const hierarchy::ProgressiveStep& s = pm.steps[order[id].cluster];
        const std::vector<uint8_t> chains = encode_chains(s.chains);
        geometry.mesh = &s.mesh;
        geometry.first_vertex = s.first_vertex;
        geometry.preserve_order = true;
        geometry.index_end = pm.vertices;
        geometry.extra = chains;
        encoded[r] = codec.encode(geometry, ps.representations[order[id].mesh].grid);
        return;
      }
      const uint32_t m = order[id].mesh;
      std::vector<uint8_t> bytes;
      if (order[id].cluster < early[m].size()) bytes = std::move(early[m][order[id].cluster]);
      if (bytes.empty()) {  // not encoded during the build (the roots)
        std::vector<uint32_t> clusters;
        for (size_t k = 0; k < batch[r].count; ++k) clusters.push_back(order[id + k].cluster);
        bytes = encode_record(codec, dags[m], clusters, batch[r].stored, grids[m]);
      }
      encoded[r] = std::move(bytes);
    });
    for (size_t r = 0; r < batch.size(); ++r) {
      if (batch[r].count == 0) {
        writer.end_group();
        continue;
      }
      const NodeSizeBreakdown b = codec.breakdown(encoded[r], args.output);
      breakdown.header += b.header, breakdown.vertices += b.vertices, breakdown.locked += b.locked;
      breakdown.indices += b.indices;
      std::vector<uint32_t> ids(batch[r].count);
      std::iota(ids.begin(), ids.end(), uint32_t(batch[r].first));
      writer.add_record(ids, encoded[r]);
    }
  }
  encoded = {};
  early = {};
  size_t stored_triangles = 0;
  for (const NodeRecord& n : records) stored_triangles += n.triangles;
  int grid_bits = 14;
  for (size_t m = 0; m < grids.size(); ++m) grid_bits = std::max(grid_bits, grids[m].bits(bounds[m]));
  size_t hlod_triangles = 0;
  for (const hierarchy::HlodNode& n : hlod.nodes) hlod_triangles += n.mesh.triangle_count();
  size_t progressive = 0;
  for (const hierarchy::ProgressiveSteps& pm : pms) progressive += !pm.steps.empty();
  nlohmann::json metadata = {{"baker", "lodstream bake"},
                             {"normal_bits", args.normal_bits},
                             {"coarse_normal_bits", args.coarse_normal_bits},
                             {"grid_bits_max", grid_bits},
                             {"hlod", !hlod.nodes.empty()},
                             {"pm_max_triangles", args.pm_max_triangles}};
  ps.metadata = metadata.dump();
  EmbeddedTextures textures = embed_textures(scene.materials, writer);
  ps.materials = std::move(textures.materials);
  const WrittenPackage written = writer.finish(std::move(ps), std::move(records), root_nodes);
  end_phase("encode_write");  // node records, encoding (not of DAG clusters), pages, index, textures
  const double time_s = elapsed();
  const uint64_t rss = peak_rss_bytes();
  const double per_triangle = double(written.bytes) / double(std::max<uint64_t>(1, input_triangles));

  if (args.json) {
    const double raw = double(std::max<size_t>(1, breakdown.total()));
    print_json({{"input_triangles", input_triangles},
                {"unique_triangles", unique_triangles},
                {"objects", scene.objects.size()},
                {"representations", dags.size()},
                {"progressive_meshes", progressive},
                {"nodes", written.nodes},
                {"root_nodes", root_nodes},
                {"pages", written.pages},
                {"levels", levels},
                {"bytes", written.bytes},
                {"bytes_per_input_triangle", per_triangle},
                {"stored_triangles", stored_triangles},
                {"grid_bits_max", grid_bits},
                {"hlod",
                 {{"nodes", hlod.nodes.size()},
                  {"levels", hlod.levels},
                  {"triangles", hlod_triangles},
                  {"root_index_nodes", hlod_top},
                  {"time_s", hlod_time}}},
                {"root_index_bytes", written.root_index_bytes},
                {"index_bytes", written.index_bytes},
                {"page_bytes", written.page_bytes},
                {"texture_bytes", textures.bytes},
                {"raw_share",
                 {{"header", breakdown.header / raw},
                  {"vertices", breakdown.vertices / raw},
                  {"locked", breakdown.locked / raw},
                  {"indices", breakdown.indices / raw}}},
                {"fallbacks",
                 {{"partial", partial},
                  {"positions_only", positions_only},
                  {"dropped_components", dropped_components},
                  {"abandoned", abandoned},
                  {"stalled_meshes", stalled}}},
                {"time_s", time_s},
                {"phases", phases},
                {"triangles_per_s", double(input_triangles) / time_s},
                {"peak_rss_bytes", rss}});
  } else {
    std::printf(
        "%s: %llu input triangles, %zu objects, %u nodes (%zu triangles stored), %u pages, %u levels\n",
        args.output.c_str(), (unsigned long long)input_triangles, scene.objects.size(), written.nodes,
        stored_triangles, written.pages, levels);
    std::printf(
        "  %llu bytes (%.3f per input triangle; root index %llu), %.2f s (%.0f triangles/s), peak RSS %.1f "
        "MB\n",
        (unsigned long long)written.bytes, per_triangle, (unsigned long long)written.root_index_bytes, time_s,
        double(input_triangles) / time_s, double(rss) / 1e6);
    if (textures.bytes)
      std::printf("  embedded textures: %llu bytes (in the bytes above)\n",
                  (unsigned long long)textures.bytes);
    if (progressive)
      std::printf("  %zu of %zu meshes are progressive meshes (at most %u triangles)\n", progressive,
                  pms.size(), args.pm_max_triangles);
    std::printf(
        "  fallbacks: %zu partial, %zu positions-only, %zu dropped components, %zu abandoned groups, "
        "%zu stalled meshes\n",
        partial, positions_only, dropped_components, abandoned, stalled);
    if (!hlod.nodes.empty())
      std::printf("  hlod: %zu proxies (%zu triangles), %u levels, %.2f s\n", hlod.nodes.size(),
                  hlod_triangles, hlod.levels, hlod_time);
  }
  return 0;
}

const bool registered = register_command(
    {"bake", "build the multiresolution package (.lods) of one or more models", [](CLI::App& sub) {
       auto args = std::make_shared<BakeArgs>();
       sub.add_option("MODEL", args->models, "input models (PLY, OBJ, OFF, or any format assimp reads)")
           ->required();
       sub.add_option("-o,--output", args->output, "the package to write (.lods)")->required();
       sub.add_option(
           "--normal-bits", args->normal_bits,
           "octahedral normal bits per component at level 0 and in progressive meshes (4..16, default 9)");
       sub.add_option(
           "--coarse-normal-bits", args->coarse_normal_bits,
           "at most this many normal bits in clusters coarser than level 0, one less from an error of 16 "
           "finest grid steps (4..16, default 7)");
       sub.add_option("--codec", args->codec,
                      "node codec: 3 = edge-front connectivity, predicted positions and normals (default; "
                      "23-31 % smaller than 1, decodes at about 0.9x its speed), 1 = meshoptimizer's codecs, "
                      "2 = 3's predictions with meshoptimizer's index codec");
       sub.add_option("--max-grid-bits", args->max_grid_bits,
                      "finest grid: at most 2^-N of a mesh's diagonal (14..20, default 20), fewer when its "
                      "vertices stay apart with fewer");
       sub.add_option("--pm-max-triangles", args->pm_max_triangles,
                      "meshes of at most N triangles become progressive meshes streamed as growing prefixes, "
                      "larger ones cluster DAGs (0 = every mesh a DAG; at most " +
                          std::to_string(kMaxPmTriangles) + "; default " +
                          std::to_string(kDefaultPmMaxTriangles) + ")");
       const hierarchy::DagOptions shape;
       char ratio[32];
       std::snprintf(ratio, sizeof ratio, "%g", shape.group_ratio);
       sub.add_option(
           "--group-ratio", args->dag.group_ratio,
           "each group of clusters is simplified to this fraction of its triangles, which sets how "
           "many levels the DAG has and how many triangles it stores (0.1..0.75, default " +
               std::string(ratio) + ")");
       sub.add_option("--group-clusters", args->dag.group_clusters,
                      "clusters per group simplified together (2..31, default " +
                          std::to_string(shape.group_clusters) + ")");
       sub.add_option("--cluster-triangles", args->cluster_triangles,
                      "at most this many triangles (and vertices, at most 255) per DAG cluster, the unit of "
                      "selection (a multiple of 4 in 16..512, default " +
                          std::to_string(shape.max_cluster_triangles) + ")");
       sub.add_flag(
           "--hlod,!--no-hlod", args->hlod,
           "an HLOD over the objects (merged proxies: a distant group of objects is a few nodes); on "
           "by default for a scene of two or more objects, --no-hlod turns it off");
       sub.add_flag("--json", args->json,
                    "print one JSON object: input_triangles, objects, nodes, pages, levels, bytes, time_s, "
                    "peak_rss_bytes, phases (wall and CPU seconds of import, hierarchy, hlod, encode_write)");
       return [args] { return run_bake(*args); };
     }});

}  // namespace
}  // namespace lodstream::cli
