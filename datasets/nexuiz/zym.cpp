#include "datasets/nexuiz/zym.hpp"

#include <cmath>

#include "datasets/byte_reader.hpp"
#include "framework/geometry/mesh.hpp"

namespace skinlab::datasets::nexuiz {
namespace {

constexpr std::size_t kHeaderSize = 140, kSceneSize = 76, kBoneSize = 40, kVertexSize = 16,
                      kPoseMatrixSize = 48, kNameSize = 32;
constexpr std::int32_t kSceneNoLoop = 1;
enum Lump {
  kScenes,
  kPoses,
  kBones,
  kVertBoneCounts,
  kVerts,
  kTexCoords,
  kRender,
  kShaders,
  kTriZone
};
const char* const kLumpNames[] = {
    "scenes lump",   "poses lump",     "bones lump",       "vertex bone counts lump",
    "vertices lump", "texcoords lump", "render list lump", "shaders lump",
    "trizone lump"};

std::string idx(const char* what, std::size_t i) {
  return std::string(what) + " " + std::to_string(i);
}

}  // namespace

ZymFile read_zym(std::string_view bytes, const std::string& source) {
  const ByteReader r(bytes, source, ByteReader::Endian::kBig);
  if (r.bytes(0, 12, "header magic") != "ZYMOTICMODEL") {
    r.fail(0, "header magic", "not a ZYM file (expected \"ZYMOTICMODEL\")");
  }
  r.require(0, kHeaderSize, "header");
  const std::int32_t type = r.i32(12, "header type");
  if (type != 1)
    r.fail(12, "header type", "type " + std::to_string(type) + " is not supported (only 1)");
  const std::int32_t filesize = r.i32(16, "header file size");
  if (filesize < static_cast<std::int32_t>(kHeaderSize))
    r.fail(16, "header file size", "too small");
  r.require(0, static_cast<std::size_t>(filesize),
            "file of header size " + std::to_string(filesize));
  auto count = [&](std::size_t offset, const char* what) {
    const std::int32_t n = r.i32(offset, what);
    if (n < 0) r.fail(offset, what, "negative count " + std::to_string(n));
    return static_cast<std::size_t>(n);
  };
  const std::size_t nv = count(48, "header #vertices"), nt = count(52, "header #triangles"),
                    ns = count(56, "header #shaders"), nb = count(60, "header #bones"),
                    nsc = count(64, "header #scenes");
  std::size_t start[9], length[9];
  for (int l = 0; l < 9; ++l) {
    start[l] = count(68 + 8 * l, kLumpNames[l]);
    length[l] = count(72 + 8 * l, kLumpNames[l]);
    r.require(start[l], length[l], kLumpNames[l]);
  }
  if (nb == 0) r.fail(60, "header #bones", "the model has no bones");

  ZymFile out;
  RiggedModel& m = out.model;
  // Bones.
  if (length[kBones] < nb * kBoneSize) {
    r.fail(start[kBones], kLumpNames[kBones],
           "holds " + std::to_string(length[kBones]) + " bytes, " + std::to_string(nb) +
               " bones need " + std::to_string(nb * kBoneSize));
  }
  for (std::size_t b = 0; b < nb; ++b) {
    const std::size_t o = start[kBones] + kBoneSize * b;
    m.joint_names.push_back(r.cstring(o, kNameSize, idx("bone", b) + " name"));
    const std::int32_t parent = r.i32(o + 36, idx("bone", b) + " parent");
    if (parent >= static_cast<std::int32_t>(b)) {
      r.fail(o + 36, idx("bone", b) + " '" + m.joint_names.back() + "'",
             "parent " + std::to_string(parent) + " does not precede the bone");
    }
    m.parents.push_back(parent < 0 ? -1 : parent);
  }

  // Vertex influences: one bone and a bone-space origin each.
  if (length[kVertBoneCounts] < nv * 4) {
    r.fail(start[kVertBoneCounts], kLumpNames[kVertBoneCounts], "shorter than #vertices × 4");
  }
  std::vector<int> vertex_bone(nv);
  std::vector<Eigen::Vector3d> origin(nv);
  const std::size_t verts_end = start[kVerts] + length[kVerts];
  for (std::size_t v = 0, o = start[kVerts]; v < nv; ++v, o += kVertexSize) {
    const std::size_t co = start[kVertBoneCounts] + 4 * v;
    const std::int32_t influences = r.i32(co, idx("vertex", v) + " bone count");
    if (influences != 1) {
      r.fail(co, idx("vertex", v) + " bone count",
             std::to_string(influences) +
                 " bones; ZYM stores no weight per influence, so only 1 is supported "
                 "(as in DarkPlaces)");
    }
    if (o + kVertexSize > verts_end) {
      r.fail(o, idx("vertex", v), "runs past the end of the vertices lump");
    }
    const std::int32_t bone = r.i32(o, idx("vertex", v) + " bone");
    if (bone < 0 || bone >= static_cast<std::int32_t>(nb)) {
      r.fail(o, idx("vertex", v),
             "bone " + std::to_string(bone) + " outside 0…" + std::to_string(nb - 1));
    }
    vertex_bone[v] = bone;
    origin[v] = Eigen::Vector3d(r.f32(o + 4, idx("vertex", v)), r.f32(o + 8, idx("vertex", v)),
                                r.f32(o + 12, idx("vertex", v)));
    if (!origin[v].allFinite()) r.fail(o, idx("vertex", v), "non-finite origin");
  }
  // Only the bones that skin vertices and their ancestors must have proper transforms. Helper
  // bones outside that set (exporter roots like "smdimport", camera targets, weapon attachment
  // points like "shotgun") often have all-zero matrices: they are marked `unusable` and
  // to_source_rig prunes them with their (unweighted) subtrees.
  std::vector<bool> checked(nb, false);
  for (int bone : vertex_bone) {
    for (int j = bone; j >= 0 && !checked[j]; j = m.parents[j]) checked[j] = true;
  }
  m.unusable.assign(nb, false);

  // Poses: parent-relative 3×4 matrices, composed to global transforms. The exporter scales
  // the model (`modelscale`) through the root bones' matrices, so global linear parts are
  // s·R with one uniform s for the whole file. Vertices are placed with the full matrices; the
  // stored transforms keep R and t only, which leaves every skinning transform
  // G_f · G_bind⁻¹ = [R_f R_bᵀ | t_f − R_f R_bᵀ t_b] unchanged, because s cancels.
  if (length[kPoses] == 0 || length[kPoses] % (nb * kPoseMatrixSize) != 0) {
    r.fail(start[kPoses], kLumpNames[kPoses],
           std::to_string(length[kPoses]) + " bytes is not a positive multiple of #bones × 48");
  }
  const std::size_t num_poses = length[kPoses] / (nb * kPoseMatrixSize);
  out.poses.reserve(num_poses);
  double scale = 0;
  std::vector<Eigen::Affine3d> bind_full;
  for (std::size_t p = 0; p < num_poses; ++p) {
    std::vector<Eigen::Affine3d> global(nb);
    Transforms rigid(nb);
    for (std::size_t b = 0; b < nb; ++b) {
      const std::size_t o = start[kPoses] + kPoseMatrixSize * (p * nb + b);
      const std::string what = idx("pose", p) + " " + idx("bone", b);
      Eigen::Affine3d local = Eigen::Affine3d::Identity();
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 4; ++col)
          local.matrix()(row, col) = r.f32(o + 16 * row + 4 * col, what);
      }
      if (!local.matrix().allFinite()) r.fail(o, what, "non-finite matrix");
      global[b] = m.parents[b] < 0 ? local : global[m.parents[b]] * local;
      const double det = global[b].linear().determinant();
      const double s = std::cbrt(det);
      if (!checked[b]) {
        rigid[b] = Eigen::Isometry3d::Identity();
        rigid[b].translation() = global[b].translation();
        const Eigen::Matrix3d R = global[b].linear() / s;
        if (s > 0 && (scale == 0 || std::abs(s - scale) <= 1e-3 * scale) &&
            (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() <= 1e-3 && R.allFinite()) {
          rigid[b].linear() = R;
        } else {
          m.unusable[b] = true;
        }
        continue;
      }
      if (scale == 0) scale = s;
      if (!(s > 0) || std::abs(s - scale) > 1e-3 * scale) {
        r.fail(o, what,
               "global scale " + std::to_string(s) + " differs from the model's " +
                   std::to_string(scale) + " (only one uniform scale is supported)");
      }
      try {
        rigid[b] = to_isometry(global[b].linear() / s, global[b].translation(), what);
      } catch (const geometry::GeometryError& e) {
        r.fail(o, what, e.what());
      }
    }
    if (p == 0) bind_full = global;
    out.poses.push_back(std::move(rigid));
  }
  m.bind = out.poses[0];
  m.V.resize(static_cast<Eigen::Index>(nv), 3);
  std::vector<Eigen::Triplet<double>> triplets;
  for (std::size_t v = 0; v < nv; ++v) {
    m.V.row(v) = (bind_full[vertex_bone[v]] * origin[v]).transpose();
    triplets.emplace_back(static_cast<int>(v), vertex_bone[v], 1.0);
  }
  m.W.resize(static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(nb));
  m.W.setFromTriplets(triplets.begin(), triplets.end());

  // Render list: per shader a triangle count, then the triangles.
  if (length[kRender] != ns * 4 + nt * 12) {
    r.fail(start[kRender], kLumpNames[kRender],
           std::to_string(length[kRender]) + " bytes, expected #shaders × 4 + #triangles × 12 = " +
               std::to_string(ns * 4 + nt * 12));
  }
  m.F.resize(static_cast<Eigen::Index>(nt), 3);
  std::size_t o = start[kRender];
  std::size_t t = 0;
  for (std::size_t s = 0; s < ns; ++s) {
    const std::size_t n = count(o, (idx("shader", s) + " triangle count").c_str());
    o += 4;
    if (t + n > nt)
      r.fail(o - 4, idx("shader", s), "more triangles than the header's " + std::to_string(nt));
    for (std::size_t k = 0; k < n; ++k, ++t, o += 12) {
      for (int c = 0; c < 3; ++c) {
        const std::int32_t vi = r.i32(o + 4 * c, idx("triangle", t));
        if (vi < 0 || vi >= static_cast<std::int32_t>(nv)) {
          r.fail(o, idx("triangle", t),
                 "vertex index " + std::to_string(vi) + " outside 0…" + std::to_string(nv) + ")");
        }
        m.F(t, 2 - c) = vi;  // clockwise on file, counter-clockwise here
      }
    }
    out.shader_names.push_back(
        r.cstring(start[kShaders] + kNameSize * s, kNameSize, idx("shader", s) + " name"));
  }
  if (t != nt)
    r.fail(start[kRender], kLumpNames[kRender],
           "holds " + std::to_string(t) + " triangles, the header says " + std::to_string(nt));

  // Scenes.
  if (length[kScenes] < nsc * kSceneSize)
    r.fail(start[kScenes], kLumpNames[kScenes], "shorter than #scenes × 76");
  for (std::size_t s = 0; s < nsc; ++s) {
    const std::size_t so = start[kScenes] + kSceneSize * s;
    const std::string what = idx("scene", s);
    ZymScene scene;
    scene.name = r.cstring(so, kNameSize, what + " name");
    scene.fps = r.f32(so + 60, what);
    scene.loop = (r.i32(so + 64, what) & kSceneNoLoop) == 0;
    scene.first_pose = r.i32(so + 68, what);
    scene.num_poses = r.i32(so + 72, what);
    if (scene.first_pose < 0 || scene.num_poses < 0 ||
        static_cast<std::size_t>(scene.first_pose) + scene.num_poses > num_poses) {
      r.fail(so, what + " '" + scene.name + "'",
             "poses " + std::to_string(scene.first_pose) + " + " + std::to_string(scene.num_poses) +
                 " exceed the file's " + std::to_string(num_poses));
    }
    out.scenes.push_back(std::move(scene));
  }
  return out;
}

ZymFile read_zym_file(const std::filesystem::path& file) {
  const std::string bytes = read_binary_file(file);
  return read_zym(bytes, file.string());
}

}  // namespace skinlab::datasets::nexuiz
