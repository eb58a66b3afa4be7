// The GPU side of a client's cut (what `view` and `render` of a package draw): each drawn mesh (a decoded
// record, its clusters drawn as ranges, or an assembled prefix: CutItem::mesh_key) uploaded to a Renderer
// once, when a cut first draws any of it, and kept while cuts draw it (released after `keep_frames` frames
// without), and the package's materials' textures uploaded once (again when CutGeometry installs an
// embedded texture read in the background); so that a frame uploads only the records new to it. Needs the
// renderer's context current on the calling thread (one thread).
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "render/renderer.hpp"
#include "render/scene_upload.hpp"
#include "runtime/cut_geometry.hpp"

namespace lodstream::cli {

class CutDrawer {
 public:
  // `renderer` must outlive this object; `materials`: the package's (CutGeometry::materials()).
  CutDrawer(render::Renderer& renderer, const std::vector<Material>& materials, uint64_t keep_frames = 30);
  ~CutDrawer();  // releases every mesh and texture uploaded here
  CutDrawer(const CutDrawer&) = delete;
  CutDrawer& operator=(const CutDrawer&) = delete;

  // The draw items of `geometry`'s current cut (after its update()), uploading the meshes new to the GPU
  // (preparing their drawn ranges, and those newly drawn of meshes already there) and releasing those
  // undrawn for keep_frames calls. Cost: the new meshes' upload and new ranges' preparation (renderer.hpp).
  const std::vector<render::DrawItem>& items(const runtime::CutGeometry& geometry);
  // Warnings of the materials' upload (an unreadable texture file).
  const std::vector<std::string>& warnings() const { return textures_.warnings; }

 private:
  struct Uploaded {
    render::MeshHandle mesh = 0;
    uint64_t last_drawn = 0;
  };
  render::Renderer& renderer_;
  render::SceneUpload textures_;  // only its textures and warnings are used
  std::vector<render::DrawMaterial> materials_;
  uint64_t materials_version_ = 0;  // CutGeometry::materials_version() of materials_
  uint64_t keep_frames_, frame_ = 0;
  std::unordered_map<uint64_t, Uploaded> meshes_;  // by CutItem::mesh_key
  std::vector<render::DrawItem> items_;
};

}  // namespace lodstream::cli
