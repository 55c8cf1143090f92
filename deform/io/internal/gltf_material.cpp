#include "deform/io/internal/gltf_material.h"

#include <tiny_gltf.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "deform/io/internal/gltf_view.h"

namespace deform::internal {
namespace {

using base::ErrorCode;

constexpr int kMaxTextureSide = 8192;  // 8192^2 texels: 768 MiB of linear floats

// The 8-bit sRGB codes in linear light (decoding an image maps each texel once).
const std::array<float, 256>& Srgb8ToLinear() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int c = 0; c < 256; ++c) t[static_cast<std::size_t>(c)] = SrgbToLinear(static_cast<float>(c) / 255.0f);
    return t;
  }();
  return table;
}

TextureWrap WrapOf(int gl_mode) {
  switch (gl_mode) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return TextureWrap::kClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return TextureWrap::kMirroredRepeat;
    default: return TextureWrap::kRepeat;  // REPEAT, and the default for unknown values
  }
}

}  // namespace

float SrgbToLinear(float encoded) {
  const double c = std::clamp(static_cast<double>(encoded), 0.0, 1.0);
  return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

base::Result<TextureImage> DecodeTextureImage(std::span<const unsigned char> bytes,
                                              const std::string& mime_type, const std::string& file,
                                              const std::string& field) {
  static constexpr unsigned char kPng[] = {0x89, 'P', 'N', 'G'};
  static constexpr unsigned char kJpeg[] = {0xff, 0xd8, 0xff};
  const char* name = nullptr;  // OpenImageIO picks its reader from the extension
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), kPng, 4) == 0) name = "texture.png";
  if (bytes.size() >= 3 && std::memcmp(bytes.data(), kJpeg, 3) == 0) name = "texture.jpg";
  if (name == nullptr) {
    return GltfError(file, ErrorCode::kUnsupported, field,
                     "image is neither PNG nor JPEG (" + std::to_string(bytes.size()) +
                         " bytes, MIME type '" + mime_type + "')");
  }
  OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // colour as stored, not premultiplied by alpha
  void* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto in = OIIO::ImageInput::open(name, &config, &reader);
  if (!in) {
    return GltfError(file, ErrorCode::kSyntax, field,
                     "cannot decode the image: " + OIIO::geterror());
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.width > kMaxTextureSide || spec.height > kMaxTextureSide ||
      spec.nchannels < 1 || spec.nchannels > 4) {
    return GltfError(file, ErrorCode::kLimitExceeded, field,
                     "image of " + std::to_string(spec.width) + " x " +
                         std::to_string(spec.height) + " x " + std::to_string(spec.nchannels) +
                         " is outside 1..8192 texels a side, 1..4 channels");
  }
  const auto texels = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height);
  const auto channels = static_cast<std::size_t>(spec.nchannels);
  TextureImage out;
  out.width = spec.width;
  out.height = spec.height;
  out.rgb.resize(texels * 3);
  // Grey (+ alpha) copies its one value to r, g and b; alpha is dropped.
  auto source_channel = [&](std::size_t c) { return channels < 3 ? 0 : c; };
  if (spec.format == OIIO::TypeDesc::UINT8) {
    std::vector<unsigned char> raw(texels * channels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, raw.data())) {
      return GltfError(file, ErrorCode::kSyntax, field,
                       "cannot decode the image: " + in->geterror());
    }
    const std::array<float, 256>& lut = Srgb8ToLinear();
    for (std::size_t t = 0; t < texels; ++t)
      for (std::size_t c = 0; c < 3; ++c) out.rgb[t * 3 + c] = lut[raw[t * channels + source_channel(c)]];
  } else {
    std::vector<float> raw(texels * channels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, raw.data())) {
      return GltfError(file, ErrorCode::kSyntax, field,
                       "cannot decode the image: " + in->geterror());
    }
    for (std::size_t t = 0; t < texels; ++t)
      for (std::size_t c = 0; c < 3; ++c) out.rgb[t * 3 + c] = SrgbToLinear(raw[t * channels + source_channel(c)]);
  }
  out.encoded.assign(bytes.begin(), bytes.end());
  out.mime_type = std::string(name).ends_with(".png") ? "image/png" : "image/jpeg";
  return out;
}

GltfMaterialReader::GltfMaterialReader(const tinygltf::Model& model, const std::string& path)
    : m_(model), path_(path), image_slot_(model.images.size(), -1) {}

base::Result<int> GltfMaterialReader::Image(int image, std::vector<base::Warning>& warnings) {
  const std::string at = Indexed("images", image);
  if (image < 0 || image >= static_cast<int>(m_.images.size())) {
    return GltfError(path_, ErrorCode::kNotFound, at,
                     "image out of range (the file has " + std::to_string(m_.images.size()) + ")");
  }
  int& slot = image_slot_[static_cast<std::size_t>(image)];
  if (slot != -1) return slot;
  const tinygltf::Image& src = m_.images[static_cast<std::size_t>(image)];
  std::span<const unsigned char> bytes;
  if (src.bufferView >= 0) {
    // Bounds of the view and its buffer, checked before reading (tinygltf does not).
    if (src.bufferView >= static_cast<int>(m_.bufferViews.size())) {
      return GltfError(path_, ErrorCode::kNotFound, at + ".bufferView",
                       "buffer view " + std::to_string(src.bufferView) + " out of range");
    }
    const tinygltf::BufferView& view = m_.bufferViews[static_cast<std::size_t>(src.bufferView)];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(m_.buffers.size()) ||
        view.byteOffset > m_.buffers[static_cast<std::size_t>(view.buffer)].data.size() ||
        view.byteLength > m_.buffers[static_cast<std::size_t>(view.buffer)].data.size() - view.byteOffset) {
      return GltfError(path_, ErrorCode::kCountMismatch, Indexed("bufferViews", src.bufferView),
                       "the image's bytes lie outside its buffer");
    }
    bytes = std::span<const unsigned char>(m_.buffers[static_cast<std::size_t>(view.buffer)].data)
                .subspan(view.byteOffset, view.byteLength);
  } else {
    bytes = src.image;  // a data: URI or file, captured undecoded by the loader
  }
  if (bytes.empty()) {
    warnings.push_back({{path_, 0, 0, at + ".uri"},
                        "image '" + src.uri + "' could not be read; its texture is left out (grey)"});
    slot = -2;
    return slot;
  }
  auto decoded = DecodeTextureImage(bytes, src.mimeType, path_, at);
  if (!decoded.ok()) return std::move(decoded).error();
  images_.push_back(std::make_shared<const TextureImage>(std::move(decoded).value()));
  slot = static_cast<int>(images_.size()) - 1;
  return slot;
}

base::Result<Material> GltfMaterialReader::Read(int index, bool has_uvs,
                                                const std::string& primitive_field,
                                                std::vector<base::Warning>& warnings) {
  Material out;
  if (index < 0) return out;
  const std::string at = Indexed("materials", index);
  if (index >= static_cast<int>(m_.materials.size())) {
    return GltfError(path_, ErrorCode::kNotFound, primitive_field + ".material",
                     "material " + std::to_string(index) + " out of range (the file has " +
                         std::to_string(m_.materials.size()) + ")");
  }
  const tinygltf::Material& src = m_.materials[static_cast<std::size_t>(index)];
  out.name = src.name;
  const std::vector<double>& f = src.pbrMetallicRoughness.baseColorFactor;
  if (f.size() >= 3) out.base_color_factor = glm::clamp(glm::vec3(glm::dvec3(f[0], f[1], f[2])), 0.0f, 1.0f);
  const tinygltf::TextureInfo& info = src.pbrMetallicRoughness.baseColorTexture;
  if (info.index < 0) return out;
  const std::string tat = at + ".pbrMetallicRoughness.baseColorTexture";
  if (info.index >= static_cast<int>(m_.textures.size())) {
    return GltfError(path_, ErrorCode::kNotFound, tat + ".index",
                     "texture " + std::to_string(info.index) + " out of range (the file has " +
                         std::to_string(m_.textures.size()) + ")");
  }
  if (info.texCoord != 0) {
    warnings.push_back({{path_, 0, 0, tat + ".texCoord"}, "only TEXCOORD_0 is imported; texture left out"});
    return out;
  }
  if (!has_uvs) {
    warnings.push_back({{path_, 0, 0, primitive_field + ".attributes"},
                        "textured material without TEXCOORD_0; texture left out"});
    return out;
  }
  const tinygltf::Texture& texture = m_.textures[static_cast<std::size_t>(info.index)];
  if (texture.source < 0) {
    warnings.push_back({{path_, 0, 0, Indexed("textures", info.index) + ".source"},
                        "texture without a source image (or only an extension's); left out"});
    return out;
  }
  auto slot = Image(texture.source, warnings);
  if (!slot.ok()) return std::move(slot).error();
  if (*slot < 0) return out;
  out.texture = *slot;
  if (texture.sampler >= 0) {
    if (texture.sampler >= static_cast<int>(m_.samplers.size())) {
      return GltfError(path_, ErrorCode::kNotFound, Indexed("textures", info.index) + ".sampler",
                       "sampler " + std::to_string(texture.sampler) + " out of range");
    }
    const tinygltf::Sampler& s = m_.samplers[static_cast<std::size_t>(texture.sampler)];
    out.wrap_s = WrapOf(s.wrapS);
    out.wrap_t = WrapOf(s.wrapT);
  }
  return out;
}

}  // namespace deform::internal
