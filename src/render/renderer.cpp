#include "render/renderer.hpp"

#include <epoxy/gl.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "render/depth_range.hpp"

namespace lodstream::render {

namespace {

// Attribute locations shared by the vertex layout and the shader.
enum : GLuint { kPosition = 0, kNormal = 1, kUv = 2, kColor = 3 };
// Uniform locations.
enum : GLint { kModelViewProjection = 0, kNormalMatrix = 1, kBaseColor = 2 };
// Shader variants: only what a draw uses is interpolated (llvmpipe's cost grows with every varying).
constexpr unsigned kTexturedVariant = 1, kColoredVariant = 2;

const char* const kVertexShader = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 0) uniform mat4 u_model_view_projection;
layout(location = 1) uniform mat3 u_normal_matrix;  // object to view space, inverse transpose
out vec3 v_normal;
#ifdef TEXTURED
layout(location = 2) in vec2 a_uv;
out vec2 v_uv;
#endif
#ifdef COLORED
layout(location = 3) in vec4 a_color;
out vec4 v_color;
#endif
void main() {
  gl_Position = u_model_view_projection * vec4(a_position, 1.0);
  v_normal = u_normal_matrix * a_normal;
#ifdef TEXTURED
  v_uv = a_uv;
#endif
#ifdef COLORED
  v_color = a_color;
#endif
}
)";

// Headlight Lambert (see renderer.hpp), then the sRGB transfer function (IEC 61966-2-1).
const char* const kFragmentShader = R"(
in vec3 v_normal;
#ifdef TEXTURED
in vec2 v_uv;
layout(binding = 0) uniform sampler2D u_base_color_texture;
#endif
#ifdef COLORED
in vec4 v_color;
#endif
layout(location = 2) uniform vec4 u_base_color;
layout(location = 0) out vec4 frag_color;
vec3 encode_srgb(vec3 c) {
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
void main() {
  vec4 albedo = u_base_color;
#ifdef TEXTURED
  albedo *= texture(u_base_color_texture, v_uv);
#endif
#ifdef COLORED
  albedo *= v_color;
#endif
  float len = length(v_normal);
  float lambert = len > 0.0 ? abs(v_normal.z) / len : 1.0;
  vec3 c = albedo.rgb * (AMBIENT + (1.0 - AMBIENT) * lambert);
  frag_color = vec4(encode_srgb(clamp(c, 0.0, 1.0)), 1.0);
}
)";

GLuint compile(GLenum stage, const std::string& source) {
  GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof log - 1, nullptr, log);
    glDeleteShader(shader);
    for (char& c : log)
      if (c == '\n') c = ' ';
    throw Error(std::string("renderer: shader does not compile: ") + log);
  }
  return shader;
}

void check_gl(const char* what) {
  GLenum error = glGetError();
  if (error == GL_NO_ERROR) return;
  while (glGetError() != GL_NO_ERROR) {
  }
  throw Error(
      std::string("renderer: ") + what + " failed (" +
      (error == GL_OUT_OF_MEMORY ? std::string("out of GPU memory") : "GL error " + std::to_string(error)) +
      ")");
}

}  // namespace

Renderer::Renderer(Context& context, const RendererOptions& options) : options_(options) {
  context.make_current();
  if (options_.msaa > 1) {
    GLint max_samples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    if (options_.msaa > max_samples)
      throw Error("msaa " + std::to_string(options_.msaa) + " exceeds this GL's maximum of " +
                  std::to_string(max_samples) + " samples");
  }
  for (unsigned variant = 0; variant < programs_.size(); ++variant) {
    std::string header = "#version 450 core\n#define AMBIENT " + std::to_string(kAmbient) + "\n";
    if (variant & kTexturedVariant) header += "#define TEXTURED\n";
    if (variant & kColoredVariant) header += "#define COLORED\n";
    GLuint vs = compile(GL_VERTEX_SHADER, header + kVertexShader);
    GLuint fs = compile(GL_FRAGMENT_SHADER, header + kFragmentShader);
    GLuint program = programs_[variant] = glCreateProgram();
    glAttachShader(program, vs);
    glAttachShader(program, fs);
    glLinkProgram(program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) throw Error("renderer: shader program does not link");
  }
  check_gl("shader setup");
}

Renderer::~Renderer() {
  for (MeshHandle h = 1; h <= meshes_.size(); ++h) release_mesh(h);
  for (TextureHandle h = 1; h <= textures_.size(); ++h) release_texture(h);
  release_frame();
  for (GLuint program : programs_) glDeleteProgram(program);
}

namespace {

// `indices` (triangles) reordered for the vertex cache into `out`, shifted down by their lowest first so that
// the reordering's tables span their vertices, not the whole mesh's (a package record's ranges, its clusters,
// each use a band of its vertices): under callgrind, `render` of motorBike's package at 1 px (near camera,
// every range of the drawn records reordered), meshopt_optimizeVertexCache 438.0 -> 337.3 M instructions.
// The order comes out the same whatever the vertices' numbers (meshoptimizer 0.18 breaks ties by cache
// position and triangle order only; tests/render: a range draws as the range alone).
void reorder_for_vertex_cache(std::span<const uint32_t> indices, uint32_t* out) {
  uint32_t lowest = UINT32_MAX, end = 0;
  for (uint32_t v : indices) lowest = std::min(lowest, v), end = std::max(end, v + 1);
  std::vector<uint32_t> shifted(indices.size());
  for (size_t i = 0; i < indices.size(); ++i) shifted[i] = indices[i] - lowest;
  meshopt_optimizeVertexCache(out, shifted.data(), indices.size(), end - lowest);
  for (size_t i = 0; i < indices.size(); ++i) out[i] += lowest;
}

}  // namespace

MeshHandle Renderer::upload_mesh(const Mesh& mesh, std::span<const uint32_t> range_triangles) {
  uint64_t ranged = 0;
  for (uint32_t t : range_triangles) ranged += t;
  if (!range_triangles.empty() && ranged != mesh.triangle_count())
    throw Error("renderer: a mesh's ranges hold " + std::to_string(ranged) + " triangles, the mesh " +
                std::to_string(mesh.triangle_count()));
  Mesh with_normals;
  if (!mesh.has_normals()) {
    with_normals.positions = mesh.positions;
    with_normals.indices = mesh.indices;
    compute_smooth_normals(with_normals);
  }
  const std::vector<glm::vec3>& normals = mesh.has_normals() ? mesh.normals : with_normals.normals;

  // Interleaved vertex: position, normal, [uv], [colour], all 32-bit floats.
  const bool uvs = mesh.has_uvs(), colors = mesh.has_colors();
  const size_t floats = 6 + (uvs ? 2 : 0) + (colors ? 4 : 0);
  std::vector<float> vertices(mesh.positions.size() * floats);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    float* out = &vertices[v * floats];
    std::memcpy(out, &mesh.positions[v], 12);
    std::memcpy(out + 3, &normals[v], 12);
    if (uvs) std::memcpy(out + 6, &mesh.uvs[v], 8);
    if (colors) std::memcpy(out + 6 + (uvs ? 2 : 0), &mesh.colors[v], 16);
  }

  GpuMesh gpu;
  gpu.has_uvs = uvs;
  gpu.has_colors = colors;
  // With ranges, each is reordered when first prepared (prepare_range), so that ranges never drawn cost no
  // reordering: a package record's clusters that the cut does not draw (`render` of elephant_1m's package at
  // 1 px, near camera: records of 1,059,288 triangles hold the 519,762 drawn).
  const bool later = !range_triangles.empty() && options_.optimize_vertex_cache;
  if (range_triangles.empty()) gpu.ranges.push_back({0, uint32_t(mesh.indices.size()), mesh.bounds(), true});
  for (uint32_t first = 0; uint32_t t : range_triangles) {
    GpuRange r{3 * first, 3 * t, {}, !later};
    for (uint32_t i = r.first_index; i < r.first_index + r.index_count; ++i)
      r.bounds.add(mesh.positions[mesh.indices[i]]);
    gpu.ranges.push_back(r);
    first += t;
  }
  glCreateBuffers(1, &gpu.vertex_buffer);
  glCreateBuffers(1, &gpu.index_buffer);
  // Zero-sized buffer storage is an error; an empty mesh keeps one dummy byte and draws nothing.
  glNamedBufferStorage(gpu.vertex_buffer, std::max<GLsizeiptr>(1, vertices.size() * sizeof(float)),
                       vertices.empty() ? nullptr : vertices.data(), 0);
  std::vector<uint32_t> reordered;
  if (options_.optimize_vertex_cache && range_triangles.empty() && !mesh.indices.empty()) {
    reordered.resize(mesh.indices.size());
    reorder_for_vertex_cache(mesh.indices, reordered.data());
  }
  const std::vector<uint32_t>& indices = reordered.empty() ? mesh.indices : reordered;
  glNamedBufferStorage(gpu.index_buffer, std::max<GLsizeiptr>(1, indices.size() * sizeof(uint32_t)),
                       indices.empty() ? nullptr : indices.data(), later ? GL_DYNAMIC_STORAGE_BIT : 0);
  glCreateVertexArrays(1, &gpu.vertex_array);
  const GLuint vao = gpu.vertex_array;
  glVertexArrayVertexBuffer(vao, 0, gpu.vertex_buffer, 0, GLsizei(floats * sizeof(float)));
  glVertexArrayElementBuffer(vao, gpu.index_buffer);
  auto attribute = [&](GLuint location, GLint size, GLuint offset_floats) {
    glEnableVertexArrayAttrib(vao, location);
    glVertexArrayAttribFormat(vao, location, size, GL_FLOAT, GL_FALSE, offset_floats * sizeof(float));
    glVertexArrayAttribBinding(vao, location, 0);
  };
  attribute(kPosition, 3, 0);
  attribute(kNormal, 3, 3);
  if (uvs) attribute(kUv, 2, 6);
  if (colors) attribute(kColor, 4, uvs ? 8 : 6);
  meshes_.push_back(gpu);
  check_gl("mesh upload");
  return MeshHandle(meshes_.size());
}

void Renderer::prepare_range(MeshHandle mesh, uint32_t range, const Mesh& source) {
  GpuRange& r = range_of({mesh, glm::mat4(1.0f), {}, range}, false);
  if (r.ready) return;
  if (size_t(r.first_index) + r.index_count > source.indices.size())
    throw Error("renderer: preparing range " + std::to_string(range) +
                " from a mesh it was not uploaded from");
  std::vector<uint32_t> reordered(r.index_count);
  reorder_for_vertex_cache(std::span(source.indices).subspan(r.first_index, r.index_count), reordered.data());
  glNamedBufferSubData(meshes_[mesh - 1].index_buffer, GLintptr(r.first_index) * GLintptr(sizeof(uint32_t)),
                       GLsizeiptr(r.index_count) * GLsizeiptr(sizeof(uint32_t)), reordered.data());
  r.ready = true;
  check_gl("range preparation");
}

Renderer::GpuRange& Renderer::range_of(const DrawItem& item, bool drawn) {
  GpuMesh& gpu = meshes_.at(item.mesh - 1);
  if (!gpu.vertex_array) throw Error("renderer: drawing a released mesh");
  if (item.range >= gpu.ranges.size())
    throw Error("renderer: drawing range " + std::to_string(item.range) + " of a mesh of " +
                std::to_string(gpu.ranges.size()));
  GpuRange& r = gpu.ranges[item.range];
  if (drawn && !r.ready)
    throw Error("renderer: drawing range " + std::to_string(item.range) + " before prepare_range");
  return r;
}

void Renderer::release_mesh(MeshHandle mesh) {
  GpuMesh& gpu = meshes_.at(mesh - 1);
  if (!gpu.vertex_array) return;
  glDeleteVertexArrays(1, &gpu.vertex_array);
  glDeleteBuffers(1, &gpu.vertex_buffer);
  glDeleteBuffers(1, &gpu.index_buffer);
  gpu = GpuMesh{};
}

TextureHandle Renderer::upload_texture(const Image& image) {
  GLuint texture = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  GLsizei levels = 1;
  while ((std::max(image.width, image.height) >> levels) > 0) ++levels;
  glTextureStorage2D(texture, levels, GL_SRGB8_ALPHA8, image.width, image.height);
  // Row 0 of a GL texture is v = 0, the bottom of the image; Image rows run top to bottom.
  const size_t row = size_t(image.width) * 4;
  std::vector<uint8_t> flipped(image.rgba.size());
  for (int y = 0; y < image.height; ++y)
    std::memcpy(&flipped[size_t(y) * row], &image.rgba[size_t(image.height - 1 - y) * row], row);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage2D(texture, 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE, flipped.data());
  glGenerateTextureMipmap(texture);
  glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(texture, GL_TEXTURE_WRAP_T, GL_REPEAT);
  textures_.push_back(texture);
  check_gl("texture upload");
  return TextureHandle(textures_.size());
}

void Renderer::release_texture(TextureHandle texture) {
  GLuint& name = textures_.at(texture - 1);
  if (name) glDeleteTextures(1, &name);
  name = 0;
}

void Renderer::release_frame() {
  glDeleteFramebuffers(1, &frame_.framebuffer);
  glDeleteFramebuffers(1, &frame_.resolve_framebuffer);
  glDeleteRenderbuffers(1, &frame_.color);
  glDeleteRenderbuffers(1, &frame_.depth);
  glDeleteRenderbuffers(1, &frame_.resolve_color);
  frame_ = FrameBuffers{};
}

void Renderer::ensure_frame(int width, int height) {
  if (frame_.framebuffer && frame_.width == width && frame_.height == height) return;
  release_frame();
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  if (width > max_size || height > max_size)
    throw Error("image size " + std::to_string(width) + "x" + std::to_string(height) +
                " exceeds this GL's maximum of " + std::to_string(max_size) + " pixels a side");
  const GLsizei samples = options_.msaa > 1 ? options_.msaa : 0;
  auto make_framebuffer = [&](GLuint& framebuffer, GLuint& color, GLuint* depth, GLsizei samples) {
    glCreateFramebuffers(1, &framebuffer);
    glCreateRenderbuffers(1, &color);
    glNamedRenderbufferStorageMultisample(color, samples, GL_RGBA8, width, height);
    glNamedFramebufferRenderbuffer(framebuffer, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    if (depth) {
      glCreateRenderbuffers(1, depth);
      glNamedRenderbufferStorageMultisample(*depth, samples, GL_DEPTH_COMPONENT24, width, height);
      glNamedFramebufferRenderbuffer(framebuffer, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, *depth);
    }
    if (glCheckNamedFramebufferStatus(framebuffer, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error("renderer: cannot make a " + std::to_string(width) + "x" + std::to_string(height) +
                  " framebuffer");
  };
  make_framebuffer(frame_.framebuffer, frame_.color, &frame_.depth, samples);
  if (samples) make_framebuffer(frame_.resolve_framebuffer, frame_.resolve_color, nullptr, 0);
  frame_.width = width;
  frame_.height = height;
  check_gl("framebuffer allocation");
}

double Renderer::draw(const Camera& camera, std::span<const DrawItem> items) {
  ensure_frame(camera.width, camera.height);
  world_boxes_.clear();
  for (const DrawItem& item : items)
    world_boxes_.push_back(transform_bounds(range_of(item).bounds, item.transform));
  const DepthRange range = depth_range(camera, world_boxes_);
  const glm::mat4 view = camera.view();
  const glm::mat4 view_projection =
      range.empty() ? glm::mat4(1.0f) : camera.projection(range.near_plane, range.far_plane) * view;

  glFinish();
  const auto start = std::chrono::steady_clock::now();
  glBindFramebuffer(GL_FRAMEBUFFER, frame_.framebuffer);
  glViewport(0, 0, camera.width, camera.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  const float background[4] = {kBackground[0] / 255.0f, kBackground[1] / 255.0f, kBackground[2] / 255.0f,
                               1.0f};
  const float far_depth = 1.0f;
  glClearNamedFramebufferfv(frame_.framebuffer, GL_COLOR, 0, background);
  glClearNamedFramebufferfv(frame_.framebuffer, GL_DEPTH, 0, &far_depth);
  if (!range.empty()) {
    GLuint current = 0;
    for (const DrawItem& item : items) {
      const GpuMesh& gpu = meshes_[item.mesh - 1];
      const GpuRange& r = range_of(item);
      if (r.index_count == 0) continue;
      const glm::mat4 mvp = view_projection * item.transform;
      const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(view * item.transform)));
      GLuint texture = item.material.texture ? textures_.at(item.material.texture - 1) : 0;
      const bool textured = texture && gpu.has_uvs;
      const GLuint program =
          programs_[(textured ? kTexturedVariant : 0) | (gpu.has_colors ? kColoredVariant : 0)];
      if (program != current) glUseProgram(current = program);
      glProgramUniformMatrix4fv(program, kModelViewProjection, 1, GL_FALSE, &mvp[0][0]);
      glProgramUniformMatrix3fv(program, kNormalMatrix, 1, GL_FALSE, &normal_matrix[0][0]);
      glProgramUniform4fv(program, kBaseColor, 1, &item.material.base_color[0]);
      if (textured) glBindTextureUnit(0, texture);
      glBindVertexArray(gpu.vertex_array);
      glDrawElements(GL_TRIANGLES, GLsizei(r.index_count), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(uintptr_t(r.first_index) * sizeof(uint32_t)));
    }
    glBindVertexArray(0);
  }
  if (frame_.resolve_framebuffer)
    glBlitNamedFramebuffer(frame_.framebuffer, frame_.resolve_framebuffer, 0, 0, camera.width, camera.height,
                           0, 0, camera.width, camera.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glFinish();
  const auto end = std::chrono::steady_clock::now();
  check_gl("draw");
  return std::chrono::duration<double, std::milli>(end - start).count();
}

void Renderer::present(int width, int height) const {
  if (!frame_.framebuffer) return;
  const GLuint source = frame_.resolve_framebuffer ? frame_.resolve_framebuffer : frame_.framebuffer;
  const GLenum filter = width == frame_.width && height == frame_.height ? GL_NEAREST : GL_LINEAR;
  glBlitNamedFramebuffer(source, 0, 0, 0, frame_.width, frame_.height, 0, 0, width, height,
                         GL_COLOR_BUFFER_BIT, filter);
  check_gl("present");
}

Image Renderer::read_pixels() const {
  Image image(frame_.width, frame_.height);
  if (!frame_.framebuffer) return image;
  GLuint source = frame_.resolve_framebuffer ? frame_.resolve_framebuffer : frame_.framebuffer;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, source);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<uint8_t> bottom_up(image.rgba.size());
  glReadPixels(0, 0, frame_.width, frame_.height, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  const size_t row = size_t(frame_.width) * 4;
  for (int y = 0; y < frame_.height; ++y)
    std::memcpy(&image.rgba[size_t(y) * row], &bottom_up[size_t(frame_.height - 1 - y) * row], row);
  check_gl("read back");
  return image;
}

}  // namespace lodstream::render
