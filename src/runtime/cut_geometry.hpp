// Cut geometry: the triangles of a cut's drawn nodes (a progressive mesh's drawn steps assembled into one
// mesh, the item of its last step), decoded from their data pages, placed by their objects' transforms and
// given the package's materials, as a list of items for a renderer that uploads each mesh once and draws
// triangle ranges of it (render::Renderer::upload_mesh with ranges). A cluster is a view into its decoded
// record (package/records.hpp: the record's mesh, one vertex pool, and the cluster's consecutive triangle
// range), never copied out: decoded records are cached, so a frame decodes only the records new to it, each
// new record's page unpacked once per update. Copying a cluster out of its record took 6.6 % of motorBike's
// decode time (perf, `bench decode`, main 780dbcf); without it, `bench decode --runs 1` under callgrind,
// whole program: motorBike 251.9 -> 234.1 M instructions, refined_elephant 80.64 -> 75.66 M, elephant_1m
// 942.3 -> 862.8 M. A renderer draws the same pixels either way (render::Renderer::upload_mesh). Pure
// computation (no GL, no clock); the pages come from a PageSource (a local file through the PackageReader, or
// pages already in the client's PageCache).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/scene.hpp"
#include "package/reader.hpp"
#include "runtime/cache.hpp"
#include "schedule/cut.hpp"

namespace lodstream::runtime {

// The decompressed bytes of data page `page` (what PackageReader::decode_node reads nodes from).
using PageSource = std::function<std::vector<uint8_t>(uint32_t page)>;

// Pages read from the reader's byte source (a local file or an HTTP range per page).
PageSource pages_from_reader(const package::PackageReader& reader);
// What a PageCache holds per page: the stored bytes as transferred (zstd; checked and unpacked here by the
// reader), or the page already unpacked (PackageReader::read_page's output).
enum class CachedPages { stored, unpacked };
// Pages from `cache` (package = the reader's content hash). A page that is not cached is a lodstream::Error:
// a cut draws only available nodes, so that means the cache and the NodeSource disagree.
PageSource pages_from_cache(const package::PackageReader& reader, PageCache& cache, CachedPages form);

// The package's materials as core materials: a texture path relative to the package resolves against the
// package's folder (`package_dir`); an embedded texture (a blob) is left to CutGeometry to read (the material
// has neither path nor image until then).
std::vector<Material> package_materials(const package::PackageScene& scene,
                                        const std::filesystem::path& package_dir);

// When CutGeometry reads the embedded textures (blobs) of the package's materials: `now`, all of them in the
// constructor (a local file, or a caller that may wait: `render` of a package); `background`, each on a
// thread of its own from the first update() that draws a node of its material (a streaming client: a blob
// over HTTP must not stall a frame), the material drawn in its base colour until the image has arrived.
enum class TextureLoading { now, background };

// NodeSource of a complete package read locally: every record (its index page read on first use) and every
// node available. What `render` of a package and the benchmark's reference images select from.
class ReaderNodes final : public schedule::NodeSource {
 public:
  explicit ReaderNodes(package::PackageReader& reader) : reader_(&reader) {}
  const package::NodeRecord* record(uint32_t id) const override {
    return id < reader_->node_count() ? &reader_->node(id) : nullptr;
  }
  bool available(uint32_t id) const override { return id < reader_->node_count(); }

 private:
  package::PackageReader* reader_;
};

// One drawn (object, node): the node's triangles (object space) under the object's transform; an HLOD proxy
// (object package::kNone) is world space (identity transform). The triangles are range `range` of `mesh`:
// mesh's triangles are consecutive ranges of `range_triangles[k]` triangles each (one range, all of them,
// when range_triangles is empty), as Renderer::upload_mesh takes them. For a cluster, mesh is its decoded
// record's (every cluster of the record over one vertex pool, indices in the record's numbering) and the
// ranges the record's clusters; for a progressive prefix, its assembled mesh, one range.
struct CutItem {
  uint32_t object = 0, node = 0;
  glm::mat4 transform{1.0f};                  // object to world
  const Mesh* mesh = nullptr;                 // valid until the next update()
  std::span<const uint32_t> range_triangles;  // valid until the next update()
  uint32_t range = 0;
  package::ClusterRange triangles;  // range `range`: its first triangle and count
  uint32_t material = 0;            // indexes materials()
  // Names mesh's content across updates: two items with the same key draw the same mesh (a caller keeps one
  // GPU copy per key), however often it is evicted and decoded again (a record's key is its page and offset,
  // a prefix's its last step).
  uint64_t mesh_key = 0;
};

class CutGeometry {
 public:
  // `reader` must outlive this object. `decoded_triangle_budget`: decoded records none of whose clusters the
  // current cut draws (and assembled prefixes it does not draw) are kept, for a cut that goes back to them,
  // up to this many triangles (a record's all), least recently drawn dropped first; a record that the cut
  // draws any cluster of is kept whole. Embedded textures are read from the reader's byte source as
  // `textures` says; one that cannot be read or decoded is a warning (warnings()), its material drawn in its
  // base colour.
  explicit CutGeometry(package::PackageReader& reader, const std::filesystem::path& package_dir = {},
                       uint64_t decoded_triangle_budget = 2'000'000,
                       TextureLoading textures = TextureLoading::now);

  // Makes the drawn nodes of `cut` (from select_cut over this reader's scene) ready to draw: decodes their
  // records not cached, reading each of their pages once from `pages`. Returns the number of records decoded.
  // Cost: O(drawn nodes) plus the pages' unpacking and the new records' decoding. Throws lodstream::Error
  // (from the reader or the page source) on a corrupted page or node.
  size_t update(const schedule::Cut& cut, const PageSource& pages);

  // The current cut's items, in the cut's (object, node) order.
  const std::vector<CutItem>& items() const { return items_; }
  const std::vector<Material>& materials() const { return materials_; }
  // Embedded textures that could not be read or decoded, one line each.
  const std::vector<std::string>& warnings() const { return warnings_; }
  // Embedded textures still being read in the background.
  size_t textures_pending() const { return pending_.size(); }
  // Changes whenever a texture read in the background is installed into materials() (so a caller that
  // uploaded the materials knows to upload them again).
  uint64_t materials_version() const { return materials_version_; }
  // Triangles drawn by the current cut (instances counted each time).
  uint64_t triangles() const { return triangles_; }
  // Decoded records held (drawn from or kept for later).
  size_t cached_records() const { return records_.size(); }
  // Triangles held: the decoded records' (all their clusters, drawn or not) and the assembled prefixes'.
  uint64_t held_triangles() const;

 private:
  struct Decoded {
    package::DecodedNode node;  // a record; a prefix's assembled mesh: node.mesh alone
    uint64_t last_drawn = 0;    // update() count of the last cut that drew it (any of its clusters)
  };
  // records_'s key of node `n`'s record (CutItem::mesh_key).
  static uint64_t record_key(const package::NodeRecord& n) { return uint64_t(n.page) << 32 | n.offset; }
  void evict();
  // The mesh of the progressive prefix that ends with step `last_step` (its steps decoded), assembled once
  // (package/progressive_prefix.hpp) and cached. Throws lodstream::Error on corrupted steps.
  const Mesh& prefix(uint32_t last_step);
  // Starts (background) or finishes the reading of the embedded textures that `cut` draws.
  void load_textures(const schedule::Cut& cut);
  // Installs the image `read` returns into material `material`, or records the warning it throws.
  void install_texture(uint32_t material, const std::function<std::shared_ptr<const Image>()>& read);

  package::PackageReader* reader_;
  TextureLoading texture_loading_;
  std::vector<Material> materials_;
  std::vector<bool> texture_requested_;  // per material: embedded texture asked for (or none to ask for)
  std::map<uint32_t, std::future<std::shared_ptr<const Image>>> pending_;  // by material
  std::vector<std::string> warnings_;
  uint64_t materials_version_ = 0;
  uint64_t budget_, frame_ = 0, triangles_ = 0;
  std::unordered_map<uint64_t, Decoded> records_;   // by record_key
  std::unordered_map<uint64_t, Decoded> prefixes_;  // by last step
  // Evicted records, whose buffers the next decodes reuse (PackageReader::decode_record into a DecodedNode),
  // at most kSpareRecords: a cut change that drops and adds a few hundred records then allocates for the
  // rest.
  static constexpr size_t kSpareRecords = 64;
  std::vector<package::DecodedNode> spare_;
  std::vector<CutItem> items_;
};

}  // namespace lodstream::runtime
