// The OpenGL 4.5 core renderer: meshes uploaded once, then drawn any number of times as a list of
// (mesh, transform, material) for a camera into an offscreen frame that is read back as an Image.
//
// Shading is fixed and deterministic (the same input gives the same bytes on the same GL implementation):
// a headlight along the view axis, two-sided Lambert plus a small ambient term in linear space,
//   c = albedo * (kAmbient + (1 - kAmbient) |n_view . z_view|),
//   albedo = base colour * vertex colour * texture,
// written as sRGB-encoded 8-bit RGBA (alpha 255) over a fixed background colour. No face culling (real models
// have mixed winding), depth test on a 24-bit depth buffer, no multisampling unless asked for.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <vector>

#include "core/bounds.hpp"
#include "core/camera.hpp"
#include "core/image.hpp"
#include "core/mesh.hpp"
#include "render/context.hpp"

namespace lodstream::render {

using MeshHandle = uint32_t;     // 0 is no mesh
using TextureHandle = uint32_t;  // 0 is no texture
inline constexpr TextureHandle kNoTexture = 0;

// Background pixel (sRGB-encoded RGBA) wherever nothing is drawn.
inline constexpr std::array<uint8_t, 4> kBackground{32, 36, 44, 255};
// Ambient fraction of the shading formula above.
inline constexpr float kAmbient = 0.15f;

struct DrawMaterial {
  glm::vec4 base_color{0.8f, 0.8f, 0.8f, 1.0f};  // linear RGBA
  TextureHandle texture = kNoTexture;            // base-colour texture; used only where the mesh has UVs
};

struct DrawItem {
  MeshHandle mesh = 0;
  glm::mat4 transform{1.0f};  // object to world
  DrawMaterial material;
  uint32_t range = 0;  // which of the mesh's triangle ranges is drawn (upload_mesh)
};

struct RendererOptions {
  int msaa = 0;  // samples per pixel; 0 or 1 for none (deterministic and fastest)
  // Reorder each uploaded mesh's triangles for the post-transform vertex cache (meshoptimizer's
  // optimizeVertexCache, Forsyth-style): llvmpipe shades a vertex again on every cache miss, and real models
  // come with an average cache miss ratio near 1.6 (motorBike) against 0.7 after reordering, 12-17 % less
  // draw time. Costs about 0.1 s per million triangles at upload; the image changes only where triangles tie
  // in depth.
  bool optimize_vertex_cache = true;
};

class Renderer {
 public:
  // Compiles the shaders in `context`, which must be current on this thread whenever the renderer is used.
  // Throws lodstream::Error when msaa exceeds GL_MAX_SAMPLES.
  explicit Renderer(Context& context, const RendererOptions& options = {});
  // Frees every GL object; the context must still exist and be current.
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Uploads a mesh (one vertex buffer with interleaved position, normal and, where present, UV and colour,
  // and one 32-bit index buffer) whose triangles are consecutive ranges of `range_triangles[k]` triangles
  // each (empty: one range, all of them), each drawn on its own (DrawItem::range): a package's decoded record
  // uploaded once, its clusters drawn as ranges (runtime/cut_geometry.hpp). A range is drawn as the same
  // triangles uploaded alone with their vertices compacted would be, to the pixel: its triangles reordered on
  // their own (the reordering does not depend on how vertices are numbered) and its bounds (for the depth
  // range) those of the vertices it uses (of all the mesh's vertices when there is one range). Smooth normals
  // are computed when the mesh has none (over the whole mesh); triangles are reordered when
  // options.optimize_vertex_cache: at upload for a mesh of one range, else each range by prepare_range,
  // before it is drawn. Cost: O(V + T) on the CPU, about 7 ms per million triangles of upload with llvmpipe
  // plus the reordering. Throws lodstream::Error when the ranges do not add up to the mesh's triangles or GL
  // runs out of memory.
  MeshHandle upload_mesh(const Mesh& mesh, std::span<const uint32_t> range_triangles = {});
  // Makes range `range` of `mesh` ready to draw: reorders its triangles, from `source` (the mesh uploaded),
  // unless done already (a mesh of one range, or without options.optimize_vertex_cache, is ready at upload).
  // Drawing a range not ready is a lodstream::Error. Cost: the range's reordering, about 0.1 s per million
  // triangles, once.
  void prepare_range(MeshHandle mesh, uint32_t range, const Mesh& source);
  // Frees a mesh's buffers; its handle must not be drawn again.
  void release_mesh(MeshHandle mesh);

  // Uploads an sRGB-encoded RGBA image as a mipmapped base-colour texture (sampled trilinear, repeating).
  // UV (0,0) is the image's bottom-left corner, (1,1) its top-right (the OpenGL / OBJ convention).
  TextureHandle upload_texture(const Image& image);
  void release_texture(TextureHandle texture);

  // Draws `items` for `camera` into the offscreen frame (camera.width x camera.height; reallocated when the
  // size changes) and waits for the GL to finish (glFinish). Near and far planes come from depth_range() of
  // the items' world bounds. Returns the wall-clock milliseconds from the first GL command of the frame to
  // glFinish.
  double draw(const Camera& camera, std::span<const DrawItem> items);

  // The frame of the last draw(), rows top to bottom. Cost: one glReadPixels (0.5-5 ms at 1280x720).
  Image read_pixels() const;

  // Copies the frame of the last draw() into the current context's default framebuffer (a window's back
  // buffer; WindowContext::swap_buffers shows it), scaled to width x height. Cost: one framebuffer blit.
  void present(int width, int height) const;

 private:
  struct GpuRange {
    uint32_t first_index = 0, index_count = 0;
    Bounds bounds;      // object space
    bool ready = true;  // reordered (prepare_range)
  };
  struct GpuMesh {
    uint32_t vertex_array = 0, vertex_buffer = 0, index_buffer = 0;  // 0 once released
    std::vector<GpuRange> ranges;
    bool has_uvs = false;
    bool has_colors = false;
  };
  // Item `item`'s range; throws lodstream::Error for a released mesh, a range it does not have, or (`drawn`)
  // a range not ready.
  GpuRange& range_of(const DrawItem& item, bool drawn = true);
  void ensure_frame(int width, int height);
  void release_frame();

  RendererOptions options_;
  std::array<uint32_t, 4> programs_{};  // shader variants: textured (1) | coloured (2)
  std::vector<GpuMesh> meshes_;         // handle h is meshes_[h - 1]
  std::vector<uint32_t> textures_;      // handle h is textures_[h - 1]; 0 once released
  std::vector<Bounds> world_boxes_;     // scratch for draw()
  struct FrameBuffers {
    int width = 0, height = 0;
    uint32_t framebuffer = 0, color = 0, depth = 0;  // multisampled when msaa > 1
    uint32_t resolve_framebuffer = 0, resolve_color = 0;
  } frame_;
};

}  // namespace lodstream::render
