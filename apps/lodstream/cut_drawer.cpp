#include "cut_drawer.hpp"

namespace lodstream::cli {

CutDrawer::CutDrawer(render::Renderer& renderer, const std::vector<Material>& materials, uint64_t keep_frames)
    : renderer_(renderer),
      materials_(render::upload_materials(renderer, materials, textures_)),
      keep_frames_(keep_frames) {}

CutDrawer::~CutDrawer() {
  for (auto& [node, uploaded] : meshes_) renderer_.release_mesh(uploaded.mesh);
  render::release_scene(renderer_, textures_);
}

const std::vector<render::DrawItem>& CutDrawer::items(const runtime::CutGeometry& geometry) {
  ++frame_;
  if (geometry.materials_version() != materials_version_) {
    render::release_scene(renderer_, textures_);
    textures_ = {};
    materials_ = render::upload_materials(renderer_, geometry.materials(), textures_);
    materials_version_ = geometry.materials_version();
  }
  items_.clear();
  for (const runtime::CutItem& item : geometry.items()) {
    Uploaded& u = meshes_[item.mesh_key];
    if (!u.mesh) u.mesh = renderer_.upload_mesh(*item.mesh, item.range_triangles);
    renderer_.prepare_range(u.mesh, item.range, *item.mesh);  // once per range
    u.last_drawn = frame_;
    items_.push_back({u.mesh, item.transform, materials_.at(item.material), item.range});
  }
  for (auto it = meshes_.begin(); it != meshes_.end();) {
    if (frame_ - it->second.last_drawn > keep_frames_) {
      renderer_.release_mesh(it->second.mesh);
      it = meshes_.erase(it);
    } else {
      ++it;
    }
  }
  return items_;
}

}  // namespace lodstream::cli
