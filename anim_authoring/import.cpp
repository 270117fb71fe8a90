// Character import through Assimp. The skeleton is the part of the node tree that the skin
// references (bone nodes and the nodes between them and their lowest common ancestor); a file
// without a skin (BVH) uses its animated nodes instead.

#include "anim_authoring/import.h"

#include "base/library_errors.h"

#include "anim/morph.h"
#include "anim_authoring/gltf_check.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <unordered_map>

namespace arview::authoring {
namespace {

namespace fs = std::filesystem;

Eigen::Matrix4d ToEigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

Eigen::Matrix4d GlobalTransform(const aiNode* node) {
  Eigen::Matrix4d g = Eigen::Matrix4d::Identity();
  for (const aiNode* n = node; n; n = n->mParent) g = ToEigen(n->mTransformation) * g;
  return g;
}

std::vector<const aiNode*> PathFromRoot(const aiNode* node) {
  std::vector<const aiNode*> path;
  for (const aiNode* n = node; n; n = n->mParent) path.push_back(n);
  std::reverse(path.begin(), path.end());
  return path;
}

struct NodeSelection {
  const aiNode* top = nullptr;               // lowest common ancestor of the selected nodes
  std::set<const aiNode*> members;
};

NodeSelection SelectSkeletonNodes(const aiScene* scene, const std::set<std::string>& names, const std::string& file) {
  NodeSelection sel;
  std::vector<std::vector<const aiNode*>> paths;
  for (const std::string& name : names) {
    const aiNode* n = scene->mRootNode->FindNode(name.c_str());
    if (!n) throw anim::Error(file + ": the skin names a bone '" + name + "' that is not a node of the file");
    paths.push_back(PathFromRoot(n));
  }
  std::size_t common = paths.front().size();
  for (const auto& p : paths) {
    std::size_t i = 0;
    while (i < common && i < p.size() && p[i] == paths.front()[i]) ++i;
    common = i;
  }
  sel.top = paths.front()[common - 1];
  for (const auto& p : paths)
    for (std::size_t i = common - 1; i < p.size(); ++i) sel.members.insert(p[i]);
  return sel;
}

void AddJoints(const aiNode* node, int parent, const NodeSelection& sel, anim::Skeleton& sk,
               std::unordered_map<const aiNode*, int>& index) {
  if (!sel.members.count(node)) return;
  const int j = sk.size();
  index[node] = j;
  sk.names.emplace_back(node->mName.C_Str());
  sk.parents.push_back(parent);
  sk.rest.push_back(anim::Transform::FromMatrix(ToEigen(node->mTransformation)));
  sk.inverse_bind.push_back(Eigen::Matrix4d::Identity());
  for (unsigned c = 0; c < node->mNumChildren; ++c) AddJoints(node->mChildren[c], j, sel, sk, index);
}

std::vector<Eigen::Matrix4d> RestModel(const anim::Skeleton& sk) {
  std::vector<Eigen::Matrix4d> g(sk.size());
  for (int j = 0; j < sk.size(); ++j)
    g[j] = (sk.parents[j] < 0 ? sk.root_parent : g[sk.parents[j]]) * sk.rest[j].ToMatrix();
  return g;
}

struct Influence {
  int joint;
  float weight;
};

// Applies `m` to a mesh's positions and its inverse transpose to its normals (either alone when
// the other flag is off).
void BakeTransform(anim::Mesh& mesh, const Eigen::Matrix4d& m, bool positions = true, bool normals = true) {
  if (m.isIdentity(1e-12)) return;
  const Eigen::Matrix3f a = m.block<3, 3>(0, 0).cast<float>();
  const Eigen::Vector3f t = m.block<3, 1>(0, 3).cast<float>();
  const Eigen::Matrix3f n = a.inverse().transpose();
  if (positions)
    for (auto& p : mesh.positions) p = a * p + t;
  if (normals)
    for (auto& v : mesh.normals) v = (n * v).normalized();
}

void FinishInfluences(anim::Mesh& mesh, std::vector<std::vector<Influence>>& inf, int fallback_joint) {
  mesh.joints.resize(mesh.positions.size());
  mesh.weights.resize(mesh.positions.size());
  for (std::size_t v = 0; v < inf.size(); ++v) {
    auto& list = inf[v];
    std::sort(list.begin(), list.end(), [](const Influence& a, const Influence& b) { return a.weight > b.weight; });
    if (list.size() > 4) list.resize(4);
    float sum = 0;
    for (const auto& i : list) sum += i.weight;
    std::array<std::uint16_t, 4> joints{};
    Eigen::Vector4f weights = Eigen::Vector4f::Zero();
    if (sum <= 0) {  // an unweighted vertex follows the fallback joint rigidly
      joints[0] = static_cast<std::uint16_t>(fallback_joint);
      weights[0] = 1;
    } else {
      for (std::size_t i = 0; i < list.size(); ++i) {
        joints[i] = static_cast<std::uint16_t>(list[i].joint);
        weights[i] = list[i].weight / sum;
      }
    }
    mesh.joints[v] = joints;
    mesh.weights[v] = weights;
  }
}

anim::Mesh CopyGeometry(const aiMesh* m) {
  anim::Mesh mesh;
  mesh.name = m->mName.C_Str();
  mesh.material = static_cast<int>(m->mMaterialIndex);
  mesh.positions.reserve(m->mNumVertices);
  for (unsigned v = 0; v < m->mNumVertices; ++v)
    mesh.positions.emplace_back(m->mVertices[v].x, m->mVertices[v].y, m->mVertices[v].z);
  mesh.normals.resize(m->mNumVertices, Eigen::Vector3f::UnitY());
  if (m->HasNormals())
    for (unsigned v = 0; v < m->mNumVertices; ++v) {
      Eigen::Vector3f n(m->mNormals[v].x, m->mNormals[v].y, m->mNormals[v].z);
      if (n.norm() > 0) mesh.normals[v] = n.normalized();
    }
  if (m->HasTextureCoords(0)) {
    mesh.uvs.reserve(m->mNumVertices);
    for (unsigned v = 0; v < m->mNumVertices; ++v)
      mesh.uvs.emplace_back(m->mTextureCoords[0][v].x, m->mTextureCoords[0][v].y);
  }
  for (unsigned f = 0; f < m->mNumFaces; ++f) {
    const aiFace& face = m->mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines left over by triangulation
    for (int i = 0; i < 3; ++i) mesh.indices.push_back(face.mIndices[i]);
  }
  return mesh;
}

class Importer {
 public:
  Importer(const aiScene* scene, const fs::path& path) : scene_(scene), path_(path), file_(path.string()) {}

  anim::Character Run() {
    anim::Character c;
    c.source = file_;
    BuildSkeleton(c.skeleton);
    rest_model_ = RestModel(c.skeleton);
    ImportMeshes(c);
    ImportMaterials(c);
    ImportClips(c);
    anim::CheckMorphTargets(c);
    return c;
  }

 private:
  void BuildSkeleton(anim::Skeleton& sk) {
    std::set<std::string> names;
    for (unsigned i = 0; i < scene_->mNumMeshes; ++i)
      for (unsigned b = 0; b < scene_->mMeshes[i]->mNumBones; ++b)
        names.insert(scene_->mMeshes[i]->mBones[b]->mName.C_Str());
    if (names.empty())
      for (unsigned a = 0; a < scene_->mNumAnimations; ++a)
        for (unsigned ch = 0; ch < scene_->mAnimations[a]->mNumChannels; ++ch)
          names.insert(scene_->mAnimations[a]->mChannels[ch]->mNodeName.C_Str());
    // A mesh animated by its morph targets alone (AnimatedMorphCube): its node is the skeleton.
    if (names.empty()) names = MorphMeshNodes();
    if (names.empty()) throw anim::Error(file_ + ": no skeleton (no skinned mesh and no animated node)");
    const NodeSelection sel = SelectSkeletonNodes(scene_, names, file_);
    if (sel.top->mParent) sk.root_parent = GlobalTransform(sel.top->mParent);
    AddJoints(sel.top, -1, sel, sk, index_);
    if (sk.size() > 65535) throw anim::Error(file_ + ": more than 65535 joints");
  }

  // The nodes that hold a mesh with morph targets.
  std::set<std::string> MorphMeshNodes() const {
    std::set<std::string> names;
    std::vector<std::pair<const aiNode*, unsigned>> instances;
    CollectInstances(scene_->mRootNode, instances);
    for (const auto& [node, mi] : instances)
      if (scene_->mMeshes[mi]->mNumAnimMeshes > 0) names.insert(node->mName.C_Str());
    return names;
  }

  // The mesh's morph targets (aiMesh::mAnimMeshes hold absolute positions and normals) as deltas
  // from the base, in model space: the target's vertices go through the same `bakes` as the
  // mesh's before the base is subtracted. A target named as one of another mesh (glTF primitives
  // of one mesh share their targets) is the same target; unnamed ones are "<mesh>#<i>".
  void ImportMorphs(const aiMesh* m, std::span<const Eigen::Matrix4d> bakes, anim::Character& c, std::size_t mesh_index) {
    std::vector<int>& targets = mesh_targets_[m];
    targets.clear();  // a mesh instanced twice: the targets of its last copy
    const anim::Mesh& mesh = c.meshes[mesh_index];
    for (unsigned a = 0; a < m->mNumAnimMeshes; ++a) {
      const aiAnimMesh* am = m->mAnimMeshes[a];
      std::string name = am->mName.length ? am->mName.C_Str() : mesh.name + "#" + std::to_string(a);
      const std::string where = file_ + ": morph target '" + name + "' of mesh '" + mesh.name + "'";
      if (am->mNumVertices != m->mNumVertices)
        throw anim::Error(where + " has " + std::to_string(am->mNumVertices) + " vertices, the mesh " +
                          std::to_string(m->mNumVertices));
      anim::Mesh shape;
      shape.positions = mesh.positions;
      shape.normals = mesh.normals;
      if (am->mVertices) {
        shape.positions.clear();
        for (unsigned v = 0; v < am->mNumVertices; ++v)
          shape.positions.emplace_back(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
        for (const Eigen::Matrix4d& b : bakes) BakeTransform(shape, b, /*positions=*/true, /*normals=*/false);
      }
      if (am->mNormals) {
        shape.normals.clear();
        for (unsigned v = 0; v < am->mNumVertices; ++v) {
          const Eigen::Vector3f n(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
          shape.normals.push_back(n.norm() > 0 ? n.normalized() : n);
        }
        for (const Eigen::Matrix4d& b : bakes) BakeTransform(shape, b, /*positions=*/false, /*normals=*/true);
      }
      std::vector<Eigen::Vector3f> dp(mesh.positions.size()), dn(mesh.positions.size());
      for (std::size_t v = 0; v < dp.size(); ++v) {
        dp[v] = shape.positions[v] - mesh.positions[v];
        dn[v] = shape.normals[v] - mesh.normals[v];
        if (!dp[v].allFinite() || !dn[v].allFinite())
          throw anim::Error(where + " has a non-finite position or normal at vertex " + std::to_string(v));
      }
      targets.push_back(anim::AddMorphTarget(c, name, static_cast<int>(mesh_index), dp, dn));
    }
  }

  void ImportMeshes(anim::Character& c) {
    anim::Skeleton& sk = c.skeleton;
    std::vector<bool> has_bind(sk.size(), false);
    // Skinned meshes first: they define the inverse bind matrices.
    std::vector<std::pair<const aiNode*, unsigned>> instances;
    CollectInstances(scene_->mRootNode, instances);
    for (const auto& [node, mi] : instances) {
      const aiMesh* m = scene_->mMeshes[mi];
      if (m->mNumBones == 0 || m->mNumVertices == 0) continue;
      anim::Mesh mesh = CopyGeometry(m);
      std::vector<std::vector<Influence>> inf(m->mNumVertices);
      const Eigen::Matrix4d place = RestPlacement(m);
      BakeTransform(mesh, place);
      const Eigen::Matrix4d unplace = place.inverse();
      std::optional<Eigen::Matrix4d> bake;
      for (unsigned b = 0; b < m->mNumBones; ++b) {
        const aiBone* bone = m->mBones[b];
        const int j = JointOf(bone->mName.C_Str());
        const Eigen::Matrix4d offset = ToEigen(bone->mOffsetMatrix) * unplace;
        if (!has_bind[j]) {
          sk.inverse_bind[j] = offset;
          has_bind[j] = true;
        } else {
          // Another mesh bound this joint differently: v' = IB⁻¹ · offset · v keeps the skinning
          // formula, if one correction serves every bone of this mesh.
          const Eigen::Matrix4d d = sk.inverse_bind[j].inverse() * offset;
          if (!bake) bake = d;
          else if (!bake->isApprox(d, 1e-6))
            throw anim::Error(file_ + ": mesh '" + mesh.name + "' is bound with inconsistent bind matrices for bone '" +
                        sk.names[j] + "'");
        }
        for (unsigned w = 0; w < bone->mNumWeights; ++w) {
          const aiVertexWeight& vw = bone->mWeights[w];
          if (vw.mVertexId < m->mNumVertices && vw.mWeight > 0) inf[vw.mVertexId].push_back({j, vw.mWeight});
        }
      }
      if (bake) BakeTransform(mesh, *bake);
      FinishInfluences(mesh, inf, JointOf(m->mBones[0]->mName.C_Str()));
      c.meshes.push_back(std::move(mesh));
      std::vector<Eigen::Matrix4d> bakes{place};
      if (bake) bakes.push_back(*bake);
      ImportMorphs(m, bakes, c, c.meshes.size() - 1);
    }
    // Joints that no skin references: bind them where they rest.
    for (int j = 0; j < sk.size(); ++j)
      if (!has_bind[j]) sk.inverse_bind[j] = rest_model_[j].inverse();
    for (const auto& [node, mi] : instances) {
      const aiMesh* m = scene_->mMeshes[mi];
      if (m->mNumBones != 0 || m->mNumVertices == 0) continue;
      const int j = NearestJoint(node);
      anim::Mesh mesh = CopyGeometry(m);
      // At rest: model_j · IB_j · v' = G_node · v.
      const Eigen::Matrix4d place = sk.inverse_bind[j].inverse() * rest_model_[j].inverse() * GlobalTransform(node);
      BakeTransform(mesh, place);
      std::vector<std::vector<Influence>> inf(m->mNumVertices, {{j, 1.0f}});
      FinishInfluences(mesh, inf, j);
      c.meshes.push_back(std::move(mesh));
      ImportMorphs(m, std::span<const Eigen::Matrix4d>(&place, 1), c, c.meshes.size() - 1);
    }
  }

  // Where the file's rest pose puts a skinned mesh: model_j · offset_j of the bones, which
  // agree when the rest pose is the bind pose; when some bones rest elsewhere, the placement
  // most bones share. Baking it into the vertices gives model-space positions that the rest
  // pose reproduces (except under the bones that rest away from their bind pose), whatever the
  // mesh node or the exporter's axis conversion was.
  Eigen::Matrix4d RestPlacement(const aiMesh* m) const {
    std::vector<Eigen::Matrix4d> p;
    for (unsigned b = 0; b < m->mNumBones; ++b)
      p.push_back(rest_model_[JointOf(m->mBones[b]->mName.C_Str())] * ToEigen(m->mBones[b]->mOffsetMatrix));
    std::size_t best = 0, best_votes = 0;
    for (std::size_t a = 0; a < p.size(); ++a) {
      std::size_t votes = 0;
      for (const auto& q : p) votes += (q - p[a]).norm() <= 1e-5 * std::max(1.0, p[a].norm());
      if (votes > best_votes) {
        best = a;
        best_votes = votes;
      }
    }
    if (p.empty() || !p[best].allFinite() || std::abs(p[best].block<3, 3>(0, 0).determinant()) < 1e-12)
      return Eigen::Matrix4d::Identity();
    return p[best];
  }

  void CollectInstances(const aiNode* node, std::vector<std::pair<const aiNode*, unsigned>>& out) const {
    for (unsigned i = 0; i < node->mNumMeshes; ++i) out.emplace_back(node, node->mMeshes[i]);
    for (unsigned c = 0; c < node->mNumChildren; ++c) CollectInstances(node->mChildren[c], out);
  }

  int NearestJoint(const aiNode* node) const {
    for (const aiNode* n = node; n; n = n->mParent)
      if (auto it = index_.find(n); it != index_.end()) return it->second;
    return 0;
  }

  int JointOf(const std::string& name) const {
    const aiNode* n = scene_->mRootNode->FindNode(name.c_str());
    auto it = index_.find(n);
    if (it == index_.end()) throw anim::Error(file_ + ": bone '" + name + "' is not in the skeleton");
    return it->second;
  }

  void ImportMaterials(anim::Character& c) {
    std::map<std::string, int> texture_index;
    for (unsigned i = 0; i < scene_->mNumMaterials; ++i) {
      const aiMaterial* mat = scene_->mMaterials[i];
      anim::Material m;
      aiString name;
      if (mat->Get(AI_MATKEY_NAME, name) == AI_SUCCESS) m.name = name.C_Str();
      aiColor4D col;
      if (mat->Get(AI_MATKEY_BASE_COLOR, col) == AI_SUCCESS || mat->Get(AI_MATKEY_COLOR_DIFFUSE, col) == AI_SUCCESS)
        m.base_color = Eigen::Vector4f(col.r, col.g, col.b, col.a);
      aiString tex;
      if (mat->GetTexture(aiTextureType_BASE_COLOR, 0, &tex) == AI_SUCCESS ||
          mat->GetTexture(aiTextureType_DIFFUSE, 0, &tex) == AI_SUCCESS) {
        const std::string key = tex.C_Str();
        auto it = texture_index.find(key);
        if (it == texture_index.end()) {
          c.textures.push_back(LoadTexture(key));
          it = texture_index.emplace(key, static_cast<int>(c.textures.size()) - 1).first;
        }
        m.texture = it->second;
      }
      c.materials.push_back(std::move(m));
    }
  }

  anim::Texture LoadTexture(const std::string& key) const {
    anim::Texture t;
    if (const aiTexture* e = scene_->GetEmbeddedTexture(key.c_str())) {
      if (e->mHeight == 0) {
        const auto* bytes = reinterpret_cast<const std::uint8_t*>(e->pcData);
        t.encoded.assign(bytes, bytes + e->mWidth);
        t.format_hint = e->achFormatHint;
      } else {
        t.width = static_cast<int>(e->mWidth);
        t.height = static_cast<int>(e->mHeight);
        t.rgba.reserve(static_cast<std::size_t>(t.width) * t.height * 4);
        for (unsigned p = 0; p < e->mWidth * e->mHeight; ++p) {
          const aiTexel& x = e->pcData[p];
          t.rgba.insert(t.rgba.end(), {x.r, x.g, x.b, x.a});
        }
      }
      return t;
    }
    fs::path p = key;
    if (p.is_relative()) p = path_.parent_path() / p;
    t.path = fs::absolute(p).lexically_normal().string();
    return t;
  }

  void ImportClips(anim::Character& c) {
    std::set<std::string> used;
    for (unsigned a = 0; a < scene_->mNumAnimations; ++a) {
      const aiAnimation* anim = scene_->mAnimations[a];
      anim::Clip clip;
      clip.name = anim->mName.length ? anim->mName.C_Str() : "clip" + std::to_string(a);
      for (int n = 2; used.count(clip.name); ++n) clip.name = std::string(anim->mName.C_Str()) + "#" + std::to_string(n);
      used.insert(clip.name);
      clip.ticks_per_second = anim->mTicksPerSecond;
      const double tps = anim->mTicksPerSecond > 0 ? anim->mTicksPerSecond : 25.0;  // Assimp's default
      clip.duration = anim->mDuration / tps;
      clip.tracks.resize(c.skeleton.size());
      for (unsigned ch = 0; ch < anim->mNumChannels; ++ch) {
        const aiNodeAnim* na = anim->mChannels[ch];
        const aiNode* node = scene_->mRootNode->FindNode(na->mNodeName);
        auto it = index_.find(node);
        if (it == index_.end()) continue;  // animates a node outside the skeleton (e.g. a mesh node)
        anim::JointTrack& tr = clip.tracks[it->second];
        for (unsigned k = 0; k < na->mNumPositionKeys; ++k) {
          const auto& v = na->mPositionKeys[k];
          tr.translation.push_back({v.mTime / tps, Eigen::Vector3d(v.mValue.x, v.mValue.y, v.mValue.z)});
        }
        for (unsigned k = 0; k < na->mNumRotationKeys; ++k) {
          const auto& v = na->mRotationKeys[k];
          tr.rotation.push_back({v.mTime / tps, Eigen::Quaterniond(v.mValue.w, v.mValue.x, v.mValue.y, v.mValue.z).normalized()});
        }
        for (unsigned k = 0; k < na->mNumScalingKeys; ++k) {
          const auto& v = na->mScalingKeys[k];
          tr.scale.push_back({v.mTime / tps, Eigen::Vector3d(v.mValue.x, v.mValue.y, v.mValue.z)});
        }
        for (const auto* keys : {&tr.translation, &tr.scale})
          for (const auto& k : *keys)
            if (!k.value.allFinite()) throw anim::Error(file_ + ": clip '" + clip.name + "' has a non-finite key");
        for (const auto& k : tr.rotation)
          if (!k.value.coeffs().allFinite()) throw anim::Error(file_ + ": clip '" + clip.name + "' has a non-finite key");
      }
      for (unsigned ch = 0; ch < anim->mNumMorphMeshChannels; ++ch)
        ImportWeightChannel(c, clip, anim->mMorphMeshChannels[ch], tps);
      if (!(clip.duration >= 0) || !std::isfinite(clip.duration))
        throw anim::Error(file_ + ": clip '" + clip.name + "' has an invalid duration");
      c.clips.push_back(std::move(clip));
    }
  }

  // A morph channel animates the weights of a node's meshes (glTF: the node's one mesh, its
  // primitives sharing the targets); each key lists (target of the mesh, weight) pairs. One weight
  // track per target; a key for a target the mesh lacks is an error naming it.
  void ImportWeightChannel(const anim::Character& c, anim::Clip& clip, const aiMeshMorphAnim* channel, double tps) {
    const std::string node_name = channel->mName.C_Str();
    const std::string where = file_ + ": clip '" + clip.name + "'";
    const aiNode* node = scene_->mRootNode->FindNode(channel->mName);
    const std::vector<int>* targets = nullptr;
    for (unsigned i = 0; node && i < node->mNumMeshes && !targets; ++i)
      if (auto it = mesh_targets_.find(scene_->mMeshes[node->mMeshes[i]]); it != mesh_targets_.end() && !it->second.empty())
        targets = &it->second;
    if (!targets) throw anim::Error(where + " keys morph target weights of '" + node_name + "', which has no morph targets");
    std::map<int, std::vector<anim::Key<double>>> tracks;
    for (unsigned k = 0; k < channel->mNumKeys; ++k) {
      const aiMeshMorphKey& key = channel->mKeys[k];
      for (unsigned i = 0; i < key.mNumValuesAndWeights; ++i) {
        const unsigned value = key.mValues[i];
        if (value >= targets->size())
          throw anim::Error(where + ": a weight track for morph target " + std::to_string(value) + " of '" + node_name +
                            "', which has " + std::to_string(targets->size()) + " targets");
        const int target = (*targets)[value];
        if (!std::isfinite(key.mWeights[i]) || !std::isfinite(key.mTime))
          throw anim::Error(where + ": a non-finite weight key for morph target '" + c.skeleton.morph_targets[target] + "'");
        tracks[target].push_back({key.mTime / tps, key.mWeights[i]});
      }
    }
    for (auto& [target, keys] : tracks) {
      for (const anim::WeightTrack& t : clip.weight_tracks)
        if (t.target == target)
          throw anim::Error(where + " keys morph target '" + c.skeleton.morph_targets[target] + "' twice");
      clip.weight_tracks.push_back({target, std::move(keys)});
    }
  }

  const aiScene* scene_;
  fs::path path_;
  std::string file_;
  std::unordered_map<const aiNode*, int> index_;
  std::vector<Eigen::Matrix4d> rest_model_;
  std::map<const aiMesh*, std::vector<int>> mesh_targets_;  // a mesh's anim meshes → the character's targets
};

}  // namespace

namespace {
std::atomic<BuiltinCharacterProvider> builtin_provider{nullptr};
}  // namespace

bool IsBuiltinAsset(const fs::path& asset) { return asset.native().rfind(kBuiltinAssetPrefix, 0) == 0; }

void SetBuiltinCharacterProvider(BuiltinCharacterProvider provider) { builtin_provider = provider; }

namespace {

anim::Character LoadCharacterFile(const fs::path& path) {
  const std::string file = path.string();
  if (IsBuiltinAsset(path)) {
    const BuiltinCharacterProvider provider = builtin_provider.load();
    if (!provider) throw anim::Error(file + ": built-in characters are not available in this program");
    return provider(file.substr(std::string(kBuiltinAssetPrefix).size()));
  }
  std::error_code ec;
  if (!fs::exists(path, ec)) throw anim::Error(file + ": no such file");
  if (!fs::is_regular_file(path, ec)) throw anim::Error(file + ": not a regular file");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw anim::Error(file + ": cannot open for reading");
  }
  // Assimp trusts a glTF's indices and byte ranges (and crashes on a skin without inverse bind
  // matrices): the structure is checked first. Other formats go to Assimp as they are.
  if (IsGltfAsset(path)) CheckGltfStructure(path);
  Assimp::Importer importer;
  // No stand-in "skeleton mesh" for files that have bones but no skin (BVH).
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  const aiScene* scene = importer.ReadFile(
      file, aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices |
                aiProcess_LimitBoneWeights | aiProcess_SortByPType);
  if (!scene || !scene->mRootNode) {
    const std::string why = importer.GetErrorString();
    throw anim::Error(file + ": cannot read as a 3D asset" + (why.empty() ? std::string() : ": " + why));
  }
  return Importer(scene, path).Run();
}

}  // namespace

anim::Character LoadCharacter(const fs::path& path) {
  // A library's own exception (std::bad_alloc, filesystem_error, ...) leaves naming the input.
  return NamingInput<anim::Error>(path.string(), [&] { return LoadCharacterFile(path); });
}

}  // namespace arview::authoring
