// Textures read through base's checked reader (base/image_file.h): a cut or damaged texture,
// beside an asset or embedded in it, is one RenderError naming it, and libpng and libjpeg print
// nothing (cv::imread and cv::imdecode let them print their own lines first).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "anim/character.h"
#include "render/character_renderer.h"
#include "render/test_scene.h"

namespace arview::render {
namespace {

namespace fs = std::filesystem;

std::string Encoded(const char* extension) {
  cv::Mat image(32, 32, CV_8UC3);
  cv::randu(image, 0, 255);
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(extension, image, bytes));
  return {bytes.begin(), bytes.end()};
}

// Builds a renderer for a character that has only the texture `texture`; returns the error
// message ("" when it was built) and requires that nothing was printed on stderr.
std::string TextureError(const anim::Texture& texture) {
  anim::Character character;
  character.source = "/assets/robot.glb";
  character.textures = {texture};
  std::string message;
  ::testing::internal::CaptureStderr();
  try {
    CharacterRenderer renderer(testing::SharedContext().gl(), character);
  } catch (const RenderError& e) {
    message = e.what();
  }
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  return message;
}

anim::Texture Embedded(const std::string& bytes) {
  anim::Texture texture;
  texture.encoded.assign(bytes.begin(), bytes.end());
  return texture;
}

TEST(CharacterTexture, ACutOrDamagedEmbeddedTextureIsOneErrorNamingTheAsset) {
  const std::string png = Encoded(".png"), jpeg = Encoded(".jpg");
  EXPECT_EQ(TextureError(Embedded(png)), "");
  EXPECT_EQ(TextureError(Embedded(jpeg)), "");
  const std::string prefix = "/assets/robot.glb (its embedded texture): ";
  EXPECT_EQ(TextureError(Embedded(png.substr(0, png.size() / 2))).rfind(prefix + "the PNG is cut short", 0), 0u);
  EXPECT_EQ(TextureError(Embedded(jpeg.substr(0, jpeg.size() - 1))).rfind(prefix + "the JPEG is cut short", 0), 0u);
  // Zeros before EOI: the markers are intact, libjpeg warns "extraneous bytes before marker 0xd9".
  const size_t eoi = jpeg.rfind("\xff\xd9");
  const std::string padded = jpeg.substr(0, eoi) + std::string(16, '\0') + jpeg.substr(eoi);
  EXPECT_EQ(TextureError(Embedded(padded)).rfind(prefix + "damaged JPEG data (libjpeg: Corrupt JPEG data: ", 0), 0u);
}

TEST(CharacterTexture, ACutTextureFileIsOneErrorNamingItAndTheAsset) {
  const fs::path dir = fs::temp_directory_path() / ("arview_texture_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string png = Encoded(".png");
  const fs::path file = dir / "skin.png";
  std::ofstream(file, std::ios::binary) << png.substr(0, png.size() - 20);
  anim::Texture texture;
  texture.path = file.string();
  const std::string message = TextureError(texture);
  EXPECT_EQ(message.rfind(file.string() + ": the PNG is cut short", 0), 0u) << message;
  EXPECT_NE(message.find("(a texture of /assets/robot.glb)"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  texture.path = (dir / "missing.png").string();
  EXPECT_EQ(TextureError(texture).rfind(texture.path + ": ", 0), 0u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace arview::render
