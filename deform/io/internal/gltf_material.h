#pragma once
// glTF materials and textures for the import: the base colour texture's image
// decoded with OpenImageIO (PNG, JPEG; from a buffer view, a data: URI or a
// file next to the model) into linear RGB, and the sampler's wrap modes.
// Only the import's .cpp files include tiny_gltf.h; this header forward-declares it.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "deform/mesh.h"
#include "base/error.h"

namespace tinygltf {
class Model;
}

namespace deform::internal {

// The sRGB transfer function's inverse (IEC 61966-2-1): an encoded value in
// [0, 1] to linear light.
float SrgbToLinear(float encoded);

// Decodes a PNG or JPEG held in memory. Grey, grey+alpha, RGB and RGBA images
// are read (alpha dropped); 8- and 16-bit values are taken as sRGB (glTF's
// base colour texture is sRGB) and converted to linear. `encoded` and
// `mime_type` are kept in the result. Errors name `file` and `field`
// (kSyntax: not a decodable image; kLimitExceeded: over 8192 texels a side).
base::Result<TextureImage> DecodeTextureImage(std::span<const unsigned char> bytes,
                                              const std::string& mime_type, const std::string& file,
                                              const std::string& field);

// A material of the file turned into a deform::Material, decoding its base
// colour texture once per image (cache in `images`, `image_slots`).
class GltfMaterialReader {
 public:
  GltfMaterialReader(const tinygltf::Model& model, const std::string& path);

  // materials[index] (index < 0: none). The texture is dropped with a warning
  // (grey stays, as the specification allows an absent texture) when its image
  // could not be read from a file or it uses a texCoord other than 0; it is an
  // error (naming the field) when an index is out of range or the image bytes
  // do not decode. `has_uvs`: whether the primitive has TEXCOORD_0; without
  // them the texture is dropped with a warning.
  base::Result<Material> Read(int index, bool has_uvs, const std::string& primitive_field,
                              std::vector<base::Warning>& warnings);

  std::vector<std::shared_ptr<const TextureImage>>& images() { return images_; }

 private:
  base::Result<int> Image(int image, std::vector<base::Warning>& warnings);

  const tinygltf::Model& m_;
  std::string path_;
  std::vector<std::shared_ptr<const TextureImage>> images_;
  std::vector<int> image_slot_;  // file image -> index into images_, -1 not yet read, -2 unreadable
};

}  // namespace deform::internal
