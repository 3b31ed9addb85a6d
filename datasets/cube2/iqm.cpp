#include "datasets/cube2/iqm.hpp"

#include <cmath>
#include <cstring>

#include "datasets/byte_reader.hpp"

namespace skinlab::datasets::cube2 {
namespace {

constexpr char kMagic[16] = "INTERQUAKEMODEL";  // with its terminating NUL: 16 bytes
constexpr std::uint32_t kVersion = 2;
constexpr std::size_t kHeaderSize = 124;
constexpr std::size_t kMeshSize = 24, kVertexArraySize = 20, kTriangleSize = 12, kJointSize = 48,
                      kPoseSize = 88, kAnimSize = 20;
enum : std::uint32_t { kPosition = 0, kBlendIndexes = 4, kBlendWeights = 5 };
enum : std::uint32_t { kUbyte = 1, kFloat = 7 };
constexpr std::uint32_t kLoop = 1;
/// At most this many pose transforms (frames × poses, over all clips: 512 MiB) are expanded;
/// the largest of cube2-data's 99 IQM files (frankie/Frankie_Idle1.iqm) has 13364.
constexpr std::uint64_t kMaxClipTransforms = std::uint64_t{1} << 22;

std::string idx(const char* what, std::size_t i) {
  return std::string(what) + " " + std::to_string(i);
}

struct Header {
  std::uint32_t version, filesize, flags, num_text, ofs_text, num_meshes, ofs_meshes,
      num_vertexarrays, num_vertexes, ofs_vertexarrays, num_triangles, ofs_triangles, ofs_adjacency,
      num_joints, ofs_joints, num_poses, ofs_poses, num_anims, ofs_anims, num_frames,
      num_framechannels, ofs_frames, ofs_bounds;
};

/// L = Translate · Rotate · Scale with the scale required to be 1 (rigid joints only).
Eigen::Isometry3d local_transform(const ByteReader& r, std::size_t offset, const std::string& what,
                                  const float* t, const float* q, const float* s,
                                  double scale_tolerance) {
  for (int k = 0; k < 3; ++k) {
    if (!(std::abs(s[k] - 1.0f) <= scale_tolerance)) {
      r.fail(offset, what,
             "scale (" + std::to_string(s[0]) + ", " + std::to_string(s[1]) + ", " +
                 std::to_string(s[2]) + ") is not 1; scaled joints are not supported");
    }
  }
  Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);  // stored x, y, z, w
  const double norm = rotation.norm();
  if (!std::isfinite(norm) || norm < 1e-6)
    r.fail(offset, what, "rotation quaternion is zero or not finite");
  rotation.coeffs() /= norm;
  Eigen::Isometry3d L = Eigen::Isometry3d::Identity();
  L.linear() = rotation.toRotationMatrix();
  L.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  if (!L.translation().allFinite()) r.fail(offset, what, "translation is not finite");
  return L;
}

}  // namespace

IqmFile read_iqm(std::string_view bytes, const std::string& source, bool read_clips) {
  const ByteReader r(bytes, source, ByteReader::Endian::kLittle);
  if (r.bytes(0, 16, "header magic") != std::string_view(kMagic, 16)) {
    r.fail(0, "header magic", "not an IQM file (expected \"INTERQUAKEMODEL\")");
  }
  r.require(0, kHeaderSize, "header");
  static_assert(sizeof(Header) == 23 * 4);
  std::uint32_t fields[23];
  for (std::size_t k = 0; k < 23; ++k) fields[k] = r.u32(16 + 4 * k, "header");
  Header h;
  std::memcpy(&h, fields, sizeof h);
  if (h.version != kVersion) {
    r.fail(16, "header version",
           "version " + std::to_string(h.version) + " is not supported (only version 2)");
  }
  r.require(0, h.filesize, "file of header size " + std::to_string(h.filesize));

  IqmFile out;
  auto text = [&](std::uint32_t offset, const std::string& what) {
    if (offset >= h.num_text && !(offset == 0 && h.num_text == 0)) {
      r.fail(h.ofs_text + offset, what,
             "string offset " + std::to_string(offset) + " is outside the text table of " +
                 std::to_string(h.num_text) + " bytes");
    }
    return h.num_text == 0 ? std::string() : r.cstring(h.ofs_text + offset, 0, what);
  };

  // Meshes: named ranges of vertices and triangles.
  for (std::uint32_t m = 0; m < h.num_meshes; ++m) {
    const std::size_t o = h.ofs_meshes + kMeshSize * m;
    const std::string what = idx("mesh", m);
    r.require(o, kMeshSize, what);
    out.mesh_names.push_back(text(r.u32(o, what), what + " name"));
    const std::uint64_t first_v = r.u32(o + 8, what), num_v = r.u32(o + 12, what);
    const std::uint64_t first_t = r.u32(o + 16, what), num_t = r.u32(o + 20, what);
    if (first_v + num_v > h.num_vertexes || first_t + num_t > h.num_triangles) {
      r.fail(o, what,
             "vertex or triangle range exceeds the file's " + std::to_string(h.num_vertexes) +
                 " vertices / " + std::to_string(h.num_triangles) + " triangles");
    }
  }

  // Vertex arrays.
  const std::size_t nv = h.num_meshes > 0 ? h.num_vertexes : 0;
  std::size_t pos_ofs = 0, index_ofs = 0, weight_ofs = 0;
  bool has_pos = false, has_index = false, has_weight = false;
  for (std::uint32_t a = 0; a < h.num_vertexarrays && nv > 0; ++a) {
    const std::size_t o = h.ofs_vertexarrays + kVertexArraySize * a;
    const std::string what = idx("vertex array", a);
    const std::uint32_t type = r.u32(o, what), format = r.u32(o + 8, what),
                        size = r.u32(o + 12, what), offset = r.u32(o + 16, what);
    auto expect = [&](std::uint32_t f, std::uint32_t s, const char* name) {
      if (format != f || size != s) {
        r.fail(o, what + " (" + name + ")",
               "format " + std::to_string(format) + " × " + std::to_string(size) +
                   " components is not supported (expected " + (f == kFloat ? "float" : "ubyte") +
                   " × " + std::to_string(s) + ")");
      }
    };
    if (type == kPosition) {
      expect(kFloat, 3, "position");
      r.require(offset, nv * 12, what + " (position data)");
      pos_ofs = offset, has_pos = true;
    } else if (type == kBlendIndexes) {
      expect(kUbyte, 4, "blend indexes");
      r.require(offset, nv * 4, what + " (blend index data)");
      index_ofs = offset, has_index = true;
    } else if (type == kBlendWeights) {
      expect(kUbyte, 4, "blend weights");
      r.require(offset, nv * 4, what + " (blend weight data)");
      weight_ofs = offset, has_weight = true;
    }
  }
  if (nv > 0 && !has_pos) r.fail(h.ofs_vertexarrays, "vertex arrays", "no position array");

  RiggedModel& model = out.model;
  model.V.resize(static_cast<Eigen::Index>(nv), 3);
  for (std::size_t v = 0; v < nv; ++v) {
    for (int k = 0; k < 3; ++k) {
      model.V(v, k) = r.f32(pos_ofs + 12 * v + 4 * k, idx("vertex", v) + " position");
    }
  }
  const std::size_t nt = h.num_meshes > 0 ? h.num_triangles : 0;
  r.require(h.ofs_triangles, nt * kTriangleSize,
            "triangles (" + std::to_string(nt) + " in the header)");  // before allocating
  model.F.resize(static_cast<Eigen::Index>(nt), 3);
  for (std::size_t t = 0; t < nt; ++t) {
    const std::size_t o = h.ofs_triangles + kTriangleSize * t;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = r.u32(o + 4 * k, idx("triangle", t));
      if (v >= nv) {
        r.fail(o, idx("triangle", t),
               "vertex index " + std::to_string(v) + " ≥ #vertices " + std::to_string(nv));
      }
      model.F(t, k) = static_cast<int>(v);
    }
  }

  // Joints: names, parents, base pose composed to global bind transforms.
  Transforms local;
  for (std::uint32_t j = 0; j < h.num_joints; ++j) {
    const std::size_t o = h.ofs_joints + kJointSize * j;
    const std::string what = idx("joint", j);
    r.require(o, kJointSize, what);
    model.joint_names.push_back(text(r.u32(o, what), what + " name"));
    const std::int32_t parent = r.i32(o + 4, what);
    if (parent >= static_cast<std::int32_t>(j)) {
      r.fail(o + 4, what, "parent " + std::to_string(parent) + " does not precede the joint");
    }
    model.parents.push_back(parent < 0 ? -1 : parent);
    float f[10];
    for (int k = 0; k < 10; ++k) f[k] = r.f32(o + 8 + 4 * k, what);
    local.push_back(
        local_transform(r, o, what + " '" + model.joint_names.back() + "'", f, f + 3, f + 7, 1e-3));
  }
  model.bind = compose_global(local, model.parents, model.joint_names, source);

  // Blend weights per joint, renormalised from uint8 (nominally summing to 255).
  if (nv > 0 && has_index && has_weight && h.num_joints > 0) {
    out.has_blend_weights = true;
    std::vector<Eigen::Triplet<double>> triplets;
    for (std::size_t v = 0; v < nv; ++v) {
      int sum = 0;
      for (int k = 0; k < 4; ++k)
        sum += r.u8(weight_ofs + 4 * v + k, idx("vertex", v) + " blend weights");
      if (sum == 0)
        r.fail(weight_ofs + 4 * v, idx("vertex", v) + " blend weights", "all four weights are 0");
      for (int k = 0; k < 4; ++k) {
        const int w = r.u8(weight_ofs + 4 * v + k, idx("vertex", v) + " blend weights");
        if (w == 0) continue;
        const int j = r.u8(index_ofs + 4 * v + k, idx("vertex", v) + " blend indexes");
        if (j >= static_cast<int>(h.num_joints)) {
          r.fail(index_ofs + 4 * v + k, idx("vertex", v) + " blend indexes",
                 "joint " + std::to_string(j) + " ≥ #joints " + std::to_string(h.num_joints));
        }
        triplets.emplace_back(static_cast<int>(v), j, double(w) / sum);
      }
    }
    model.W.resize(static_cast<Eigen::Index>(nv), h.num_joints);
    model.W.setFromTriplets(triplets.begin(), triplets.end());  // duplicates are summed
  }

  if (!read_clips) return out;

  // Poses, frames, animations.
  struct Pose {
    std::uint32_t mask;
    float offset[10], scale[10];
  };
  r.require(h.ofs_poses, std::size_t(h.num_poses) * kPoseSize,
            "poses (" + std::to_string(h.num_poses) + " in the header)");  // before allocating
  std::vector<Pose> poses(h.num_poses);
  std::size_t channels = 0;
  for (std::uint32_t p = 0; p < h.num_poses; ++p) {
    const std::size_t o = h.ofs_poses + kPoseSize * p;
    const std::string what = idx("pose", p);
    r.require(o, kPoseSize, what);
    const std::int32_t parent = r.i32(o, what);
    if (parent >= static_cast<std::int32_t>(p)) {
      r.fail(o, what, "parent " + std::to_string(parent) + " does not precede the pose");
    }
    out.pose_parents.push_back(parent < 0 ? -1 : parent);
    poses[p].mask = r.u32(o + 4, what);
    for (int c = 0; c < 10; ++c) {
      poses[p].offset[c] = r.f32(o + 8 + 4 * c, what);
      poses[p].scale[c] = r.f32(o + 48 + 4 * c, what);
      if (poses[p].mask & (1u << c)) ++channels;
    }
  }
  if (h.num_frames > 0 && channels != h.num_framechannels) {
    r.fail(h.ofs_poses, "poses",
           "channel masks select " + std::to_string(channels) +
               " channels per frame, the header says " + std::to_string(h.num_framechannels));
  }
  r.require(h.ofs_frames, std::size_t(2) * h.num_frames * h.num_framechannels, "frame data");
  auto frame_locals = [&](std::uint32_t frame) {
    Transforms out_frame(h.num_poses);
    std::size_t o = h.ofs_frames + std::size_t(2) * frame * h.num_framechannels;
    for (std::uint32_t p = 0; p < h.num_poses; ++p) {
      float ch[10];
      for (int c = 0; c < 10; ++c) {
        ch[c] = poses[p].offset[c];
        if (poses[p].mask & (1u << c)) {
          ch[c] += r.u16(o, idx("frame", frame)) * poses[p].scale[c];
          o += 2;
        }
      }
      // Animation scales are quantised to 16 bits: allow a little more than for joints.
      out_frame[p] =
          local_transform(r, h.ofs_frames + std::size_t(2) * frame * h.num_framechannels,
                          idx("frame", frame) + " " + idx("pose", p), ch, ch + 3, ch + 7, 1e-2);
    }
    return out_frame;
  };
  std::uint64_t transforms = 0;
  for (std::uint32_t a = 0; a < h.num_anims; ++a) {
    const std::size_t o = h.ofs_anims + kAnimSize * a;
    const std::string what = idx("animation", a);
    r.require(o, kAnimSize, what);
    IqmClip clip;
    clip.name = text(r.u32(o, what), what + " name");
    const std::uint64_t first = r.u32(o + 4, what), count = r.u32(o + 8, what);
    clip.fps = r.f32(o + 12, what);
    clip.loop = (r.u32(o + 16, what) & kLoop) != 0;
    if (first + count > h.num_frames) {
      r.fail(o, what + " '" + clip.name + "'",
             "frames " + std::to_string(first) + "…" + std::to_string(first + count) +
                 " exceed the file's " + std::to_string(h.num_frames) + " frames");
    }
    // A frame stores 2 bytes per animated channel only, and clips may share frames, so the
    // transforms the clips expand to are not bounded by the file's size.
    transforms += count * h.num_poses;
    if (transforms > kMaxClipTransforms) {
      r.fail(o, what + " '" + clip.name + "'",
             "the clips expand to more than " + std::to_string(kMaxClipTransforms) +
                 " pose transforms (" + std::to_string(count) + " frames of " +
                 std::to_string(h.num_poses) + " poses here), the reader's limit");
    }
    for (std::uint64_t f = first; f < first + count; ++f) {
      clip.local.push_back(frame_locals(static_cast<std::uint32_t>(f)));
    }
    out.clips.push_back(std::move(clip));
  }
  return out;
}

IqmFile read_iqm_file(const std::filesystem::path& file, bool read_clips) {
  const std::string bytes = read_binary_file(file);
  return read_iqm(bytes, file.string(), read_clips);
}

std::vector<Transforms> global_frames(const IqmClip& clip, const std::vector<int>& parents,
                                      const std::vector<std::string>& names,
                                      const std::string& source) {
  std::vector<Transforms> out;
  out.reserve(clip.local.size());
  for (const Transforms& frame : clip.local) {
    out.push_back(
        compose_global(frame, parents, names, source + ": animation '" + clip.name + "'"));
  }
  return out;
}

}  // namespace skinlab::datasets::cube2
