#include "runtime/cut_geometry.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <tuple>

#include "core/error.hpp"
#include "package/progressive_prefix.hpp"

namespace lodstream::runtime {

PageSource pages_from_reader(const package::PackageReader& reader) {
  return [&reader](uint32_t page) { return reader.read_page(page); };
}

PageSource pages_from_cache(const package::PackageReader& reader, PageCache& cache, CachedPages form) {
  return [&reader, &cache, form](uint32_t page) {
    const std::vector<uint8_t>* bytes = cache.find(reader.header().content_hash, page);
    if (!bytes)
      throw Error(reader.source().name() + ": page " + std::to_string(page) + " is drawn but not cached");
    return form == CachedPages::stored ? reader.unpack_page(page, *bytes) : *bytes;
  };
}

std::vector<Material> package_materials(const package::PackageScene& scene,
                                        const std::filesystem::path& package_dir) {
  std::vector<Material> materials;
  for (const package::PackageMaterial& m : scene.materials) {
    Material out = m.material;
    if (m.texture_blob != package::kNone) {
      out.base_color_texture.clear();  // read by CutGeometry
    } else if (!out.base_color_texture.empty()) {
      const std::filesystem::path texture(out.base_color_texture);
      if (texture.is_relative()) out.base_color_texture = (package_dir / texture).string();
    }
    materials.push_back(std::move(out));
  }
  if (materials.empty()) materials.emplace_back();
  return materials;
}

namespace {

// Reads and decodes embedded texture `blob` of `reader`'s package.
std::shared_ptr<const Image> read_texture(const package::PackageReader* reader, uint32_t blob) {
  const std::vector<uint8_t> bytes = reader->read_blob(blob);
  return std::make_shared<const Image>(
      decode_image(bytes, reader->source().name() + ": texture blob " + std::to_string(blob)));
}

}  // namespace

CutGeometry::CutGeometry(package::PackageReader& reader, const std::filesystem::path& package_dir,
                         uint64_t decoded_triangle_budget, TextureLoading textures)
    : reader_(&reader),
      texture_loading_(textures),
      materials_(package_materials(reader.scene(), package_dir)),
      budget_(decoded_triangle_budget) {
  const auto& stored = reader.scene().materials;
  texture_requested_.assign(materials_.size(), true);
  for (size_t m = 0; m < stored.size(); ++m) {
    if (stored[m].texture_blob == package::kNone) continue;
    if (textures == TextureLoading::background) {
      texture_requested_[m] = false;
      continue;
    }
    install_texture(uint32_t(m), [&] { return read_texture(reader_, stored[m].texture_blob); });
  }
}

void CutGeometry::install_texture(uint32_t material,
                                  const std::function<std::shared_ptr<const Image>()>& read) {
  try {
    materials_[material].base_color_image = read();
    ++materials_version_;
  } catch (const Error& e) {
    warnings_.push_back("material '" + materials_[material].name + "': " + e.what() +
                        "; drawn in its base colour");
  }
}

void CutGeometry::load_textures(const schedule::Cut& cut) {
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (it->second.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      ++it;
      continue;
    }
    install_texture(it->first, [&] { return it->second.get(); });
    it = pending_.erase(it);
  }
  for (const schedule::DrawnNode& d : cut.drawn) {
    const uint32_t m = reader_->node(d.node).material;
    if (m >= texture_requested_.size() || texture_requested_[m]) continue;
    texture_requested_[m] = true;
    pending_.emplace(
        m, std::async(std::launch::async, read_texture, reader_, reader_->scene().materials[m].texture_blob));
  }
}

size_t CutGeometry::update(const schedule::Cut& cut, const PageSource& pages) {
  ++frame_;
  load_textures(cut);
  // The nodes of records not held, grouped by page, so each page is unpacked once.
  std::map<uint32_t, std::vector<uint32_t>> missing_by_page;
  for (const schedule::DrawnNode& d : cut.drawn) {
    const package::NodeRecord& n = reader_->node(d.node);
    auto it = records_.find(record_key(n));
    if (it != records_.end())
      it->second.last_drawn = frame_;
    else
      missing_by_page[n.page].push_back(d.node);
  }
  size_t decoded = 0;
  for (const auto& [page, ids] : missing_by_page) {
    const std::vector<uint8_t> bytes = pages(page);
    for (uint32_t id : ids) {
      auto [it, inserted] = records_.try_emplace(record_key(reader_->node(id)));
      if (!inserted) continue;  // another cluster of the record, or an instanced node listed once per object
      // Into an evicted record's buffers where one is spare: no allocation.
      if (!spare_.empty()) it->second.node = std::move(spare_.back()), spare_.pop_back();
      try {
        reader_->decode_record(id, bytes, it->second.node);
        reader_->cluster_of(id, it->second.node);  // checked now: a progressive step is not an item below
      } catch (...) {
        records_.erase(it);  // a corrupted record leaves none
        throw;
      }
      it->second.last_drawn = frame_;
      ++decoded;
    }
  }
  items_.clear();
  triangles_ = 0;
  const auto& objects = reader_->scene().objects;
  for (const schedule::DrawnNode& d : cut.drawn) {
    if (d.refined) continue;  // drawn as part of its object's prefix, below
    const package::NodeRecord& n = reader_->node(d.node);
    CutItem item;
    item.object = d.object, item.node = d.node;
    item.transform = d.object == package::kNone ? glm::mat4(1.0f) : objects[d.object].transform;
    item.material = n.material < materials_.size() ? n.material : 0;
    if (n.kind == package::NodeKind::progressive_step) {
      item.mesh = &prefix(d.node);
      item.triangles = {0, uint32_t(item.mesh->triangle_count())};
      // Above every record's key: pages number fewer than 2^31 (their ranges fill a root index of <= 64 MiB).
      item.mesh_key = uint64_t(1) << 63 | d.node;
    } else {
      const package::DecodedNode& record = records_.at(record_key(n)).node;
      item.mesh = &record.mesh;
      item.range_triangles = record.cluster_triangles;
      item.range = n.cluster;
      item.triangles = reader_->cluster_of(d.node, record);
      item.mesh_key = record_key(n);
    }
    triangles_ += item.triangles.triangles;
    items_.push_back(item);
  }
  evict();
  return decoded;
}

const Mesh& CutGeometry::prefix(uint32_t last_step) {
  auto it = prefixes_.find(last_step);
  if (it == prefixes_.end()) {
    // Every step of a drawn prefix is drawn (cut.hpp), each a node of one cluster: its record is the node.
    std::vector<const package::DecodedNode*> steps;  // last first, then reversed
    for (uint32_t id = last_step;;) {
      const package::NodeRecord& r = reader_->node(id);
      steps.push_back(&records_.at(record_key(r)).node);
      if (r.parents.empty()) break;
      id = r.parents[0];
    }
    std::reverse(steps.begin(), steps.end());
    Decoded assembled;
    assembled.node.mesh = package::assemble_prefix(
        steps, reader_->source().name() + ": progressive prefix ending at node " + std::to_string(last_step));
    it = prefixes_.emplace(last_step, std::move(assembled)).first;
  }
  it->second.last_drawn = frame_;
  return it->second.node.mesh;
}

void CutGeometry::evict() {
  std::vector<std::tuple<uint64_t, bool, uint64_t>> idle;  // (last drawn, prefix?, key) not drawn now
  uint64_t idle_triangles = 0;
  for (auto* map : {&records_, &prefixes_})
    for (const auto& [key, d] : *map) {
      if (d.last_drawn == frame_) continue;
      idle.push_back({d.last_drawn, map == &prefixes_, key});
      idle_triangles += d.node.mesh.triangle_count();
    }
  if (idle_triangles <= budget_) return;
  std::sort(idle.begin(), idle.end());
  for (const auto& [last, is_prefix, key] : idle) {
    if (idle_triangles <= budget_) break;
    auto& map = is_prefix ? prefixes_ : records_;
    auto it = map.find(key);
    idle_triangles -= it->second.node.mesh.triangle_count();
    if (!is_prefix && spare_.size() < kSpareRecords) spare_.push_back(std::move(it->second.node));
    map.erase(it);
  }
}

uint64_t CutGeometry::held_triangles() const {
  uint64_t triangles = 0;
  for (const auto* map : {&records_, &prefixes_})
    for (const auto& [key, d] : *map) triangles += d.node.mesh.triangle_count();
  return triangles;
}

}  // namespace lodstream::runtime
