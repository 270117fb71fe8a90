// glTF 2.0 structure checks before Assimp (see gltf_check.h for what and why).

#include "anim_authoring/gltf_check.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "anim/character.h"
#include "anim_authoring/gltf_container.h"
#include "base/input_guard.h"

namespace arview::authoring {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace gltf;  // the container: bytes, URIs, the JSON and the GLB chunks

// No accessor of a character comes near this; it keeps every byte-range product inside 64 bits.
constexpr std::uint64_t kMaxCount = 1ull << 32;

struct AccessorShape {
  std::uint64_t component_bytes = 0;
  std::uint64_t components = 0;
  std::uint64_t element_bytes = 0;  // with the column padding of byte/short matrices
  std::string type;
  int component_type = 0;
};

class GltfChecker {
  struct View {
    std::uint64_t buffer, offset, length, stride;
  };
  struct Packed {  // a tightly packed run of elements in a bufferView (sparse indices or values)
    std::uint64_t view = 0, offset = 0;
    AccessorShape shape;
  };
  struct Accessor {
    AccessorShape shape;
    std::uint64_t count = 0;
    std::optional<std::uint64_t> view;
    std::uint64_t offset = 0;
    std::uint64_t sparse_count = 0;
    Packed sparse_indices, sparse_values;
  };
  struct JointAccessor {
    std::size_t mesh;
    std::uint64_t accessor;
    std::string where;
  };

 public:
  GltfChecker(const fs::path& file, const json& doc, std::optional<std::string_view> glb_bin)
      : file_(file), doc_(doc), glb_bin_(glb_bin) {}

  void Run() {
    if (!doc_.is_object()) Fail("the glTF JSON is not an object");
    CheckAsset();
    CheckBuffers();
    CheckBufferViews();
    CheckAccessors();
    CheckImagesTexturesMaterials();
    CheckNodes();
    CheckMeshes();
    CheckSkins();
    CheckJointValues();
    CheckAnimations();
    CheckScenes();
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw anim::Error(file_.string() + ": " + what); }

  // A file a URI names, resolved inside the asset's folder (symlinks included) or refused.
  fs::path Inside(const std::string& uri, const std::string& where) const {
    try {
      return ResolveInside(file_.parent_path(), DecodeUri(uri), file_.string() + ": " + where + ".uri");
    } catch (const InputError& e) {
      throw anim::Error(e.what());
    }
  }

  const json& Array(const char* name) const {
    static const json empty = json::array();
    if (!doc_.contains(name)) return empty;
    const json& a = doc_[name];
    if (!a.is_array()) Fail(std::string("'") + name + "' is not an array");
    return a;
  }
  std::size_t Count(const char* name) const { return Array(name).size(); }

  const json& Object(const json& array, std::size_t i, const std::string& where) const {
    const json& o = array[i];
    if (!o.is_object()) Fail(where + " is not an object");
    return o;
  }

  // A non-negative integer field (nothing when absent and not required).
  std::optional<std::uint64_t> Uint(const json& obj, const char* key, const std::string& where, bool required = false,
                                    std::uint64_t max = kMaxCount) const {
    if (!obj.contains(key)) {
      if (required) Fail(where + "." + key + " is missing");
      return std::nullopt;
    }
    const json& v = obj[key];
    if (!v.is_number_integer() || (v.is_number_integer() && !v.is_number_unsigned() && v.get<std::int64_t>() < 0))
      Fail(where + "." + key + " is not a non-negative integer");
    const std::uint64_t u = v.get<std::uint64_t>();
    if (u > max) Fail(where + "." + key + " = " + std::to_string(u) + " is larger than " + std::to_string(max));
    return u;
  }

  // An index field into the top-level array `target`.
  std::optional<std::uint64_t> Index(const json& obj, const char* key, const char* target, const std::string& where,
                                     bool required = false) const {
    const auto i = Uint(obj, key, where, required, std::numeric_limits<std::uint64_t>::max());
    if (i && *i >= Count(target))
      Fail(where + "." + key + " = " + std::to_string(*i) + " is outside '" + target + "' (" +
           std::to_string(Count(target)) + " entries)");
    return i;
  }

  std::string String(const json& obj, const char* key, const std::string& where) const {
    if (!obj.contains(key)) return {};
    if (!obj[key].is_string()) Fail(where + "." + key + " is not a string");
    return obj[key].get<std::string>();
  }

  void CheckAsset() const {
    if (!doc_.contains("asset") || !doc_["asset"].is_object()) Fail("no 'asset' object (not a glTF file)");
    const std::string version = String(doc_["asset"], "version", "asset");
    if (version.rfind("2.", 0) != 0)
      Fail("glTF version '" + version + "' is not supported (only glTF 2.x is checked and read)");
  }

  void CheckBuffers() {
    const json& buffers = Array("buffers");
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      const std::string where = "buffers[" + std::to_string(i) + "]";
      const json& b = Object(buffers, i, where);
      const std::uint64_t length = *Uint(b, "byteLength", where, true);
      if (length == 0) Fail(where + ".byteLength is 0");
      buffer_lengths_.push_back(length);
      buffer_bytes_.push_back(LoadBuffer(b, i, length, where));
    }
  }

  // The bytes of buffer i, with its length checked against where they are.
  std::string LoadBuffer(const json& b, std::size_t i, std::uint64_t length, const std::string& where) const {
    const std::string uri = String(b, "uri", where);
    if (uri.empty()) {
      if (i != 0 || !glb_bin_) Fail(where + " has no uri and is not a GLB's binary chunk");
      if (length > glb_bin_->size())
        Fail(where + ".byteLength " + std::to_string(length) + " is larger than the GLB's BIN chunk (" +
             std::to_string(glb_bin_->size()) + " bytes)");
      return std::string(*glb_bin_);
    }
    if (uri.rfind("data:", 0) == 0) {
      const std::size_t comma = uri.find(',');
      if (comma == std::string::npos || uri.substr(0, comma).find(";base64") == std::string::npos)
        Fail(where + ".uri is a data: URI that is not base64");
      const auto bytes = DecodeBase64(std::string_view(uri).substr(comma + 1));
      if (!bytes) Fail(where + ".uri is not valid base64");
      if (bytes->size() < length)
        Fail(where + ".byteLength " + std::to_string(length) + " is larger than its data: URI (" +
             std::to_string(bytes->size()) + " bytes)");
      return *bytes;
    }
    const fs::path path = Inside(uri, where);
    std::string bytes;
    try {
      bytes = ReadFileUpTo(path, kMaxAssetBytes);
    } catch (const InputError& e) {
      Fail(where + ".uri: " + e.what());
    }
    if (bytes.size() < length)
      Fail(where + ".byteLength " + std::to_string(length) + " is larger than " + path.string() + " (" +
           std::to_string(bytes.size()) + " bytes)");
    return bytes;
  }

  void CheckBufferViews() {
    const json& views = Array("bufferViews");
    for (std::size_t i = 0; i < views.size(); ++i) {
      const std::string where = "bufferViews[" + std::to_string(i) + "]";
      const json& v = Object(views, i, where);
      const std::uint64_t buffer = *Index(v, "buffer", "buffers", where, true);
      const std::uint64_t offset = Uint(v, "byteOffset", where).value_or(0);
      const std::uint64_t length = *Uint(v, "byteLength", where, true);
      if (length == 0) Fail(where + ".byteLength is 0");
      if (offset + length > buffer_lengths_[buffer])
        Fail(where + " (bytes " + std::to_string(offset) + "-" + std::to_string(offset + length) +
             ") runs past the end of buffers[" + std::to_string(buffer) + "] (" + std::to_string(buffer_lengths_[buffer]) +
             " bytes)");
      const std::uint64_t stride = Uint(v, "byteStride", where).value_or(0);
      if (v.contains("byteStride") && (stride < 4 || stride > 252 || stride % 4 != 0))
        Fail(where + ".byteStride " + std::to_string(stride) + " is not a multiple of 4 in 4-252");
      views_.push_back({buffer, offset, length, stride});
    }
  }

  AccessorShape Shape(const json& a, const std::string& where) const {
    AccessorShape s;
    if (!a.contains("componentType") || !a["componentType"].is_number_integer())
      Fail(where + ".componentType is missing or not an integer");
    s.component_type = a["componentType"].get<int>();
    switch (s.component_type) {
      case 5120: case 5121: s.component_bytes = 1; break;
      case 5122: case 5123: s.component_bytes = 2; break;
      case 5125: case 5126: s.component_bytes = 4; break;
      default: Fail(where + ".componentType " + std::to_string(s.component_type) + " is not a glTF component type");
    }
    s.type = String(a, "type", where);
    std::uint64_t columns = 1, rows = 1;
    if (s.type == "SCALAR") rows = 1;
    else if (s.type == "VEC2") rows = 2;
    else if (s.type == "VEC3") rows = 3;
    else if (s.type == "VEC4") rows = 4;
    else if (s.type == "MAT2") columns = rows = 2;
    else if (s.type == "MAT3") columns = rows = 3;
    else if (s.type == "MAT4") columns = rows = 4;
    else Fail(where + ".type '" + s.type + "' is not a glTF accessor type");
    s.components = columns * rows;
    // Matrix columns start on 4-byte boundaries (glTF 2.0, "Data Alignment").
    const std::uint64_t column_bytes = rows * s.component_bytes;
    s.element_bytes = columns > 1 ? columns * ((column_bytes + 3) / 4 * 4) : column_bytes;
    return s;
  }

  // Elements [0, count) of `shape` at `offset` in bufferView `view` (stride from the view, or packed).
  void RequireInsideView(std::uint64_t view, std::uint64_t offset, std::uint64_t count, const AccessorShape& shape,
                         const std::string& where) const {
    const std::uint64_t stride = views_[view].stride ? views_[view].stride : shape.element_bytes;
    if (views_[view].stride && views_[view].stride < shape.element_bytes)
      Fail(where + ": bufferViews[" + std::to_string(view) + "].byteStride " + std::to_string(views_[view].stride) +
           " is smaller than one element (" + std::to_string(shape.element_bytes) + " bytes)");
    const std::uint64_t end = offset + stride * (count - 1) + shape.element_bytes;
    if (end > views_[view].length)
      Fail(where + ": " + std::to_string(count) + " elements from byte " + std::to_string(offset) + " need " +
           std::to_string(end) + " bytes, bufferViews[" + std::to_string(view) + "] has " +
           std::to_string(views_[view].length));
  }

  void CheckAccessors() {
    const json& accessors = Array("accessors");
    for (std::size_t i = 0; i < accessors.size(); ++i) {
      const std::string where = "accessors[" + std::to_string(i) + "]";
      const json& a = Object(accessors, i, where);
      Accessor acc;
      acc.shape = Shape(a, where);
      acc.count = *Uint(a, "count", where, true);
      if (acc.count == 0) Fail(where + ".count is 0");
      acc.view = Index(a, "bufferView", "bufferViews", where);
      acc.offset = Uint(a, "byteOffset", where).value_or(0);
      if (acc.offset % acc.shape.component_bytes != 0)
        Fail(where + ".byteOffset " + std::to_string(acc.offset) + " is not a multiple of its component size");
      if (acc.view) RequireInsideView(*acc.view, acc.offset, acc.count, acc.shape, where);
      if (a.contains("sparse")) CheckSparse(a["sparse"], acc, where + ".sparse");
      accessors_.push_back(acc);
    }
  }

  void CheckSparse(const json& sparse, Accessor& acc, const std::string& where) const {
    if (!sparse.is_object()) Fail(where + " is not an object");
    const std::uint64_t count = *Uint(sparse, "count", where, true);
    if (count == 0 || count > acc.count)
      Fail(where + ".count " + std::to_string(count) + " is not in 1-" + std::to_string(acc.count));
    for (const char* part : {"indices", "values"}) {
      const std::string w = where + "." + part;
      if (!sparse.contains(part) || !sparse[part].is_object()) Fail(w + " is missing");
      const json& p = sparse[part];
      const std::uint64_t view = *Index(p, "bufferView", "bufferViews", w, true);
      const std::uint64_t offset = Uint(p, "byteOffset", w).value_or(0);
      AccessorShape shape = acc.shape;
      if (std::string(part) == "indices") {
        const int type = p.value("componentType", 0);
        if (type != 5121 && type != 5123 && type != 5125) Fail(w + ".componentType is not 5121, 5123 or 5125");
        shape = {static_cast<std::uint64_t>(type == 5121 ? 1 : type == 5123 ? 2 : 4), 1, 0, "SCALAR", type};
        shape.element_bytes = shape.component_bytes;
        acc.sparse_indices = {view, offset, shape};
      } else {
        acc.sparse_values = {view, offset, shape};
      }
      // Sparse data is tightly packed, whatever the view's stride.
      const std::uint64_t end = offset + count * shape.element_bytes;
      if (end > views_[view].length)
        Fail(w + ": " + std::to_string(count) + " elements need " + std::to_string(end) + " bytes, bufferViews[" +
             std::to_string(view) + "] has " + std::to_string(views_[view].length));
    }
    acc.sparse_count = count;
    // The indices must point inside the accessor.
    for (std::uint64_t k = 0; k < count; ++k) {
      const std::uint64_t index = ReadPacked(acc.sparse_indices, k, 0);
      if (index >= acc.count)
        Fail(where + ".indices[" + std::to_string(k) + "] = " + std::to_string(index) + " is outside the accessor (" +
             std::to_string(acc.count) + " elements)");
    }
  }

  void CheckImagesTexturesMaterials() const {
    const json& images = Array("images");
    for (std::size_t i = 0; i < images.size(); ++i) {
      const std::string where = "images[" + std::to_string(i) + "]";
      const json& im = Object(images, i, where);
      Index(im, "bufferView", "bufferViews", where);
      const std::string uri = String(im, "uri", where);
      if (!uri.empty() && uri.rfind("data:", 0) != 0)
        (void)Inside(uri, where);
    }
    const json& textures = Array("textures");
    for (std::size_t i = 0; i < textures.size(); ++i) {
      const std::string where = "textures[" + std::to_string(i) + "]";
      const json& t = Object(textures, i, where);
      Index(t, "source", "images", where);
      Index(t, "sampler", "samplers", where);
    }
    const json& materials = Array("materials");
    for (std::size_t i = 0; i < materials.size(); ++i) {
      const std::string where = "materials[" + std::to_string(i) + "]";
      const json& m = Object(materials, i, where);
      auto texture_info = [&](const json& holder, const char* key, const std::string& w) {
        if (!holder.contains(key)) return;
        if (!holder[key].is_object()) Fail(w + "." + key + " is not an object");
        Index(holder[key], "index", "textures", w + "." + key, true);
        Uint(holder[key], "texCoord", w + "." + key, false, 16);
      };
      if (m.contains("pbrMetallicRoughness")) {
        const json& pbr = m["pbrMetallicRoughness"];
        if (!pbr.is_object()) Fail(where + ".pbrMetallicRoughness is not an object");
        texture_info(pbr, "baseColorTexture", where + ".pbrMetallicRoughness");
        texture_info(pbr, "metallicRoughnessTexture", where + ".pbrMetallicRoughness");
      }
      for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"}) texture_info(m, key, where);
    }
  }

  // The node graph must be a forest: Assimp builds its node tree by recursion over children.
  void CheckNodes() {
    const json& nodes = Array("nodes");
    parent_.assign(nodes.size(), -1);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const std::string where = "nodes[" + std::to_string(i) + "]";
      const json& n = Object(nodes, i, where);
      Index(n, "mesh", "meshes", where);
      Index(n, "skin", "skins", where);
      Index(n, "camera", "cameras", where);
      if (n.contains("skin") && !n.contains("mesh")) Fail(where + " has a skin but no mesh");
      static const std::pair<const char*, int> kTransforms[] = {{"matrix", 16}, {"translation", 3}, {"rotation", 4}, {"scale", 3}};
      for (const auto& [key, size] : kTransforms) {
        if (!n.contains(key)) continue;
        const json& v = n[key];
        if (!v.is_array() || static_cast<int>(v.size()) != size ||
            !std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); }))
          Fail(where + "." + key + " is not " + std::to_string(size) + " numbers");
      }
      if (!n.contains("children")) continue;
      const json& children = n["children"];
      if (!children.is_array()) Fail(where + ".children is not an array");
      for (std::size_t c = 0; c < children.size(); ++c) {
        const std::string w = where + ".children[" + std::to_string(c) + "]";
        const json& child = children[c];
        if (!child.is_number_unsigned() || child.get<std::uint64_t>() >= nodes.size())
          Fail(w + " is not an index into 'nodes' (" + std::to_string(nodes.size()) + " entries)");
        const std::size_t k = child.get<std::size_t>();
        if (k == i) Fail(w + " is the node itself");
        if (parent_[k] >= 0)
          Fail("nodes[" + std::to_string(k) + "] is a child of both nodes[" + std::to_string(parent_[k]) + "] and " + where);
        parent_[k] = static_cast<int>(i);
      }
    }
    // With one parent each, a cycle is a walk upwards that never reaches a root.
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      std::size_t steps = 0;
      for (int n = static_cast<int>(i); n >= 0; n = parent_[n])
        if (++steps > nodes.size()) Fail("nodes[" + std::to_string(i) + "] is in a cycle of children");
    }
  }

  void CheckMeshes() {
    const json& meshes = Array("meshes");
    for (std::size_t i = 0; i < meshes.size(); ++i) {
      const std::string where = "meshes[" + std::to_string(i) + "]";
      const json& m = Object(meshes, i, where);
      if (!m.contains("primitives") || !m["primitives"].is_array() || m["primitives"].empty())
        Fail(where + ".primitives is missing or empty");
      const json& primitives = m["primitives"];
      for (std::size_t p = 0; p < primitives.size(); ++p)
        CheckPrimitive(Object(primitives, p, where + ".primitives[" + std::to_string(p) + "]"), i,
                       where + ".primitives[" + std::to_string(p) + "]");
    }
  }

  // Every attribute with one element per vertex, the indices below the vertex count.
  void CheckPrimitive(const json& p, std::size_t mesh, const std::string& where) {
    if (!p.contains("attributes") || !p["attributes"].is_object()) Fail(where + ".attributes is missing");
    const json& attributes = p["attributes"];
    const auto position = Index(attributes, "POSITION", "accessors", where + ".attributes", true);
    const std::uint64_t vertices = accessors_[*position].count;
    if (accessors_[*position].shape.type != "VEC3") Fail(where + ".attributes.POSITION is not VEC3");
    auto same_count = [&](const json& attrs, const std::string& w) {
      for (const auto& [name, value] : attrs.items()) {
        const auto a = Index(attrs, name.c_str(), "accessors", w, true);
        if (accessors_[*a].count != vertices)
          Fail(w + "." + name + " has " + std::to_string(accessors_[*a].count) + " elements, POSITION has " +
               std::to_string(vertices));
        if (name.rfind("JOINTS_", 0) == 0) {
          const AccessorShape& s = accessors_[*a].shape;
          if (s.type != "VEC4" || (s.component_type != 5121 && s.component_type != 5123))
            Fail(w + "." + name + " is not VEC4 of unsigned bytes or shorts");
          joint_accessors_.push_back({mesh, *a, w + "." + name});
        }
      }
    };
    same_count(attributes, where + ".attributes");
    if (p.contains("targets")) {
      const json& targets = p["targets"];
      if (!targets.is_array()) Fail(where + ".targets is not an array");
      for (std::size_t t = 0; t < targets.size(); ++t) {
        const std::string w = where + ".targets[" + std::to_string(t) + "]";
        if (!targets[t].is_object()) Fail(w + " is not an object");
        same_count(targets[t], w);
      }
    }
    Index(p, "material", "materials", where);
    Uint(p, "mode", where, false, 6);
    if (const auto indices = Index(p, "indices", "accessors", where)) {
      const Accessor& a = accessors_[*indices];
      if (a.shape.type != "SCALAR" || (a.shape.component_type != 5121 && a.shape.component_type != 5123 &&
                                       a.shape.component_type != 5125))
        Fail(where + ".indices is not SCALAR of unsigned bytes, shorts or ints");
      RequireValuesBelow(a, vertices, where + ".indices (accessors[" + std::to_string(*indices) + "])",
                         "the vertex count " + std::to_string(vertices));
    }
  }

  void CheckSkins() {
    const json& skins = Array("skins");
    for (std::size_t i = 0; i < skins.size(); ++i) {
      const std::string where = "skins[" + std::to_string(i) + "]";
      const json& s = Object(skins, i, where);
      if (!s.contains("joints") || !s["joints"].is_array() || s["joints"].empty())
        Fail(where + ".joints is missing or empty");
      const json& joints = s["joints"];
      for (std::size_t j = 0; j < joints.size(); ++j)
        if (!joints[j].is_number_unsigned() || joints[j].get<std::uint64_t>() >= Count("nodes"))
          Fail(where + ".joints[" + std::to_string(j) + "] is not an index into 'nodes'");
      Index(s, "skeleton", "nodes", where);
      // Optional in glTF 2.0, but Assimp 5.2's importer reads a null pointer without it.
      const auto ibm = Index(s, "inverseBindMatrices", "accessors", where);
      if (!ibm)
        Fail(where + " has no inverseBindMatrices (glTF 2.0 allows that, but the Assimp this program uses crashes "
                     "on it: export the skin with its inverse bind matrices)");
      const Accessor& a = accessors_[*ibm];
      if (a.shape.type != "MAT4" || a.shape.component_type != 5126)
        Fail(where + ".inverseBindMatrices (accessors[" + std::to_string(*ibm) + "]) is not MAT4 of floats");
      if (a.count < joints.size())
        Fail(where + ".inverseBindMatrices has " + std::to_string(a.count) + " matrices for " +
             std::to_string(joints.size()) + " joints");
      skin_joint_counts_.push_back(joints.size());
    }
  }

  // JOINTS_n values index the skin of every node that draws the mesh.
  void CheckJointValues() const {
    const json& nodes = Array("nodes");
    for (const JointAccessor& ja : joint_accessors_) {
      for (std::size_t n = 0; n < nodes.size(); ++n) {
        const json& node = nodes[n];
        if (!node.contains("skin") || node["mesh"].get<std::uint64_t>() != ja.mesh) continue;
        const std::uint64_t joints = skin_joint_counts_[node["skin"].get<std::size_t>()];
        RequireValuesBelow(accessors_[ja.accessor], joints, ja.where,
                           "the joint count " + std::to_string(joints) + " of skins[" +
                               std::to_string(node["skin"].get<std::uint64_t>()) + "] (nodes[" + std::to_string(n) + "])");
      }
    }
  }

  void CheckAnimations() const {
    const json& animations = Array("animations");
    for (std::size_t i = 0; i < animations.size(); ++i) {
      const std::string where = "animations[" + std::to_string(i) + "]";
      const json& an = Object(animations, i, where);
      if (!an.contains("samplers") || !an["samplers"].is_array()) Fail(where + ".samplers is missing");
      if (!an.contains("channels") || !an["channels"].is_array()) Fail(where + ".channels is missing");
      const json& samplers = an["samplers"];
      for (std::size_t s = 0; s < samplers.size(); ++s) {
        const std::string w = where + ".samplers[" + std::to_string(s) + "]";
        const json& sm = Object(samplers, s, w);
        const auto input = Index(sm, "input", "accessors", w, true);
        Index(sm, "output", "accessors", w, true);
        if (accessors_[*input].shape.type != "SCALAR" || accessors_[*input].shape.component_type != 5126)
          Fail(w + ".input is not SCALAR of floats");
        const std::string interpolation = String(sm, "interpolation", w);
        if (!interpolation.empty() && interpolation != "LINEAR" && interpolation != "STEP" &&
            interpolation != "CUBICSPLINE")
          Fail(w + ".interpolation '" + interpolation + "' is not LINEAR, STEP or CUBICSPLINE");
      }
      const json& channels = an["channels"];
      for (std::size_t c = 0; c < channels.size(); ++c) {
        const std::string w = where + ".channels[" + std::to_string(c) + "]";
        const json& ch = Object(channels, c, w);
        const std::uint64_t s = *Uint(ch, "sampler", w, true, std::numeric_limits<std::uint64_t>::max());
        if (s >= samplers.size()) Fail(w + ".sampler = " + std::to_string(s) + " is outside " + where + ".samplers");
        if (!ch.contains("target") || !ch["target"].is_object()) Fail(w + ".target is missing");
        const json& target = ch["target"];
        const auto node = Index(target, "node", "nodes", w + ".target");
        const std::string path = String(target, "path", w + ".target");
        CheckChannelOutput(samplers[s], path, w);
        if (path == "weights") CheckWeightsOutput(samplers[s], node, w);
      }
    }
  }

  // Assimp reads one output value (three for CUBICSPLINE) per input time.
  void CheckChannelOutput(const json& sampler, const std::string& path, const std::string& where) const {
    const Accessor& input = accessors_[sampler["input"].get<std::size_t>()];
    const Accessor& output = accessors_[sampler["output"].get<std::size_t>()];
    const std::uint64_t per_time = sampler.value("interpolation", std::string("LINEAR")) == "CUBICSPLINE" ? 3 : 1;
    std::string type;
    if (path == "translation" || path == "scale") type = "VEC3";
    else if (path == "rotation") type = "VEC4";
    else if (path == "weights") type = "SCALAR";
    else Fail(where + ".target.path '" + path + "' is not translation, rotation, scale or weights");
    if (output.shape.type != type) Fail(where + ": the " + path + " output is " + output.shape.type + ", not " + type);
    if (output.count < input.count * per_time)
      Fail(where + ": " + std::to_string(output.count) + " output values for " + std::to_string(input.count) +
           " key times" + (per_time == 3 ? " (CUBICSPLINE needs three each)" : ""));
  }

  // A weights channel keys every morph target of its node's mesh at each time (glTF 2.0 §3.11):
  // Assimp takes the targets per time from the output's length, so a short or long output would
  // pair weights with the wrong targets and times.
  void CheckWeightsOutput(const json& sampler, const std::optional<std::uint64_t>& node, const std::string& where) const {
    if (!node) Fail(where + ": a weights channel without a target node");
    const json& n = doc_.at("nodes").at(*node);
    if (!n.is_object() || !n.contains("mesh") || !n["mesh"].is_number_unsigned() ||
        n["mesh"].get<std::uint64_t>() >= Count("meshes"))
      Fail(where + ": animates the morph target weights of node " + std::to_string(*node) + ", which has no mesh");
    const std::size_t mesh_index = n["mesh"].get<std::size_t>();
    const json& mesh = doc_.at("meshes").at(mesh_index);
    std::uint64_t targets = 0;
    if (mesh.is_object() && mesh.contains("primitives") && mesh["primitives"].is_array() && !mesh["primitives"].empty() &&
        mesh["primitives"][0].is_object() && mesh["primitives"][0].contains("targets") &&
        mesh["primitives"][0]["targets"].is_array())
      targets = mesh["primitives"][0]["targets"].size();
    const bool named = mesh.is_object() && mesh.contains("name") && mesh["name"].is_string();
    const std::string mesh_name = named ? mesh["name"].get<std::string>() : "meshes[" + std::to_string(mesh_index) + "]";
    if (targets == 0)
      Fail(where + ": animates the morph target weights of mesh '" + mesh_name + "', which has no morph targets");
    const Accessor& input = accessors_[sampler["input"].get<std::size_t>()];
    const Accessor& output = accessors_[sampler["output"].get<std::size_t>()];
    const std::uint64_t per_time = (sampler.value("interpolation", std::string("LINEAR")) == "CUBICSPLINE" ? 3 : 1) * targets;
    if (output.count != input.count * per_time)
      Fail(where + ": " + std::to_string(output.count) + " weights for " + std::to_string(input.count) +
           " key times and the " + std::to_string(targets) + " morph targets of mesh '" + mesh_name + "' (" +
           std::to_string(input.count * per_time) + " expected)");
  }

  void CheckScenes() const {
    const json& scenes = Array("scenes");
    for (std::size_t i = 0; i < scenes.size(); ++i) {
      const std::string where = "scenes[" + std::to_string(i) + "]";
      const json& s = Object(scenes, i, where);
      if (!s.contains("nodes")) continue;
      if (!s["nodes"].is_array()) Fail(where + ".nodes is not an array");
      for (std::size_t k = 0; k < s["nodes"].size(); ++k)
        if (!s["nodes"][k].is_number_unsigned() || s["nodes"][k].get<std::uint64_t>() >= Count("nodes"))
          Fail(where + ".nodes[" + std::to_string(k) + "] is not an index into 'nodes'");
    }
    Index(doc_, "scene", "scenes", "the file");
  }

  std::uint64_t ReadComponent(std::uint64_t view, std::uint64_t byte, int component_type) const {
    const std::string& bytes = buffer_bytes_[views_[view].buffer];
    const std::size_t at = views_[view].offset + byte;
    if (component_type == 5121) return static_cast<std::uint8_t>(bytes[at]);
    if (component_type == 5123) {
      std::uint16_t v;
      std::memcpy(&v, bytes.data() + at, 2);
      return v;
    }
    return ReadU32(bytes, at);
  }
  std::uint64_t ReadPacked(const Packed& p, std::uint64_t element, std::uint64_t component) const {
    return ReadComponent(p.view, p.offset + element * p.shape.element_bytes + component * p.shape.component_bytes,
                         p.shape.component_type);
  }

  // Every component of an unsigned-integer accessor (dense part and sparse values) below `limit`.
  void RequireValuesBelow(const Accessor& a, std::uint64_t limit, const std::string& where,
                          const std::string& limit_name) const {
    auto check = [&](std::uint64_t value, std::uint64_t element) {
      if (value >= limit)
        Fail(where + ": element " + std::to_string(element) + " holds " + std::to_string(value) + ", not below " +
             limit_name);
    };
    if (a.view) {
      const std::uint64_t stride = views_[*a.view].stride ? views_[*a.view].stride : a.shape.element_bytes;
      for (std::uint64_t e = 0; e < a.count; ++e)
        for (std::uint64_t c = 0; c < a.shape.components; ++c)
          check(ReadComponent(*a.view, a.offset + e * stride + c * a.shape.component_bytes, a.shape.component_type), e);
    }
    for (std::uint64_t k = 0; k < a.sparse_count; ++k)
      for (std::uint64_t c = 0; c < a.shape.components; ++c)
        check(ReadPacked(a.sparse_values, k, c), ReadPacked(a.sparse_indices, k, 0));
  }

  const fs::path& file_;
  const json& doc_;
  std::optional<std::string_view> glb_bin_;
  std::vector<std::uint64_t> buffer_lengths_;
  std::vector<std::string> buffer_bytes_;
  std::vector<View> views_;
  std::vector<Accessor> accessors_;
  std::vector<int> parent_;
  std::vector<JointAccessor> joint_accessors_;
  std::vector<std::uint64_t> skin_joint_counts_;
};

void CheckGltfBytes(const fs::path& file, const std::string& bytes) {
  const bool glb = bytes.size() >= 4 && ReadU32(bytes, 0) == kGlbMagic;
  if (!glb) {
    const json doc = ParseJson(file, bytes);
    GltfChecker(file, doc, std::nullopt).Run();
    return;
  }
  const GlbChunks chunks = SplitGlb(file, bytes);
  const json doc = ParseJson(file, chunks.json);
  GltfChecker(file, doc, chunks.has_bin ? std::optional<std::string_view>(chunks.bin) : std::nullopt).Run();
}

}  // namespace

bool IsGltfAsset(const fs::path& file) {
  const std::string ext = ToLower(file.extension().string());
  if (ext == ".gltf" || ext == ".glb" || ext == ".vrm") return true;
  std::ifstream in(file, std::ios::binary);
  char magic[4] = {};
  return in.read(magic, 4) && ReadU32(std::string_view(magic, 4), 0) == kGlbMagic;
}

void CheckGltfStructure(const fs::path& file) {
  try {
    CheckGltfBytes(file, ReadAsset(file));
  } catch (const json::exception& e) {  // a field of an unexpected JSON type the checks above did not name
    throw anim::Error(file.string() + ": unexpected glTF JSON: " + e.what());
  }
}


}  // namespace arview::authoring
