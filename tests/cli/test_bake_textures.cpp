// Textures travel inside the package (issue 4: materials and textures survive and render): a textured model
// baked into a package renders with its texture after the image file is gone from the model's folder, and a
// damaged embedded texture is a warning, the material drawn in its base colour.
#include <gtest/gtest.h>

#include <fstream>

#include "core/image.hpp"
#include "support/run.hpp"

using namespace lodstream;

namespace {

// A 16 x 16 grid of quads over [-1, 1]^2 (z = 0) with UVs, one material whose base-colour map is `texture`.
void write_textured_grid(const std::filesystem::path& dir, const std::string& texture) {
  std::ofstream mtl(dir / "grid.mtl");
  mtl << "newmtl painted\nKd 1 1 1\nmap_Kd " << texture << "\n";
  std::ofstream obj(dir / "grid.obj");
  obj << "mtllib grid.mtl\n";
  const int n = 16;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      obj << "v " << -1.0 + 2.0 * x / n << " " << -1.0 + 2.0 * y / n << " 0\n";
      obj << "vt " << double(x) / n << " " << double(y) / n << "\n";
    }
  obj << "usemtl painted\n";
  auto id = [&](int x, int y) { return std::to_string(y * (n + 1) + x + 1); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const std::string a = id(x, y), b = id(x + 1, y), c = id(x + 1, y + 1), d = id(x, y + 1);
      obj << "f " << a << "/" << a << " " << b << "/" << b << " " << c << "/" << c << "\n";
      obj << "f " << a << "/" << a << " " << c << "/" << c << " " << d << "/" << d << "\n";
    }
}

// Red, green and blue of the image's centre pixel.
std::array<int, 3> centre(const std::filesystem::path& png) {
  const Image img = load_image(png);
  const uint8_t* p = img.pixel(img.width / 2, img.height / 2);
  return {p[0], p[1], p[2]};
}

}  // namespace

TEST(BakeTextures, APackageDrawsItsTextureWithoutTheModelsFolder) {
  const auto model = test::temp_dir(), away = test::temp_dir();
  Image green(4, 4);
  for (size_t i = 0; i < green.rgba.size(); i += 4)
    green.rgba[i] = 30, green.rgba[i + 1] = 200, green.rgba[i + 2] = 40, green.rgba[i + 3] = 255;
  save_png(green, model / "green.png");
  write_textured_grid(model, "green.png");
  const auto package = away / "grid.lods";
  auto bake = test::run_lodstream({"bake", (model / "grid.obj").string(), "-o", package.string()});
  ASSERT_EQ(bake.status, 0) << bake.err;
  std::filesystem::remove(model / "green.png");  // only the package has it now
  auto inspect = test::run_lodstream({"inspect", package.string(), "--verify", "--json"});
  ASSERT_EQ(inspect.status, 0) << inspect.err;
  EXPECT_EQ(inspect.json()["textures"], 1);
  EXPECT_GT(inspect.json()["texture_bytes"].get<int64_t>(), 0);

  const auto image = away / "grid.png";
  auto r = test::run_lodstream({"render", package.string(), "--eye", "0,0,3", "--target", "0,0,0",
                                "--pixel-error", "1", "-o", image.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto [red, grn, blue] = centre(image);
  EXPECT_GT(grn, 2 * red) << "the texture's green is not drawn (" << red << "," << grn << "," << blue << ")";
  EXPECT_GT(grn, 2 * blue);

  // The same package with its embedded texture damaged: a warning, and the material's base colour (white).
  std::vector<char> bytes;
  {
    std::ifstream in(package, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string png_magic = "\x89PNG";
  auto at = std::search(bytes.begin(), bytes.end(), png_magic.begin(), png_magic.end());
  ASSERT_NE(at, bytes.end()) << "the PNG is not stored in the package";
  at[20] ^= 0x5a;
  const auto damaged = away / "damaged.lods";
  std::ofstream(damaged, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  r = test::run_lodstream({"render", damaged.string(), "--eye", "0,0,3", "--target", "0,0,0", "--pixel-error",
                           "1", "-o", image.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("blob 0"), std::string::npos) << r.err;
  const auto [red2, grn2, blue2] = centre(image);
  EXPECT_LT(std::abs(grn2 - red2), 8) << "drawn " << red2 << "," << grn2 << "," << blue2;
}
