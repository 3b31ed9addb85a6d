#include "datasets/ogre/ogre_file.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>

#include "datasets/byte_reader.hpp"
#include "framework/core/error.hpp"
#include "framework/geometry/skin_weights.hpp"

namespace skinlab::datasets::ogre {

namespace {

// Chunk ids (OgreMeshFileFormat.h, OgreSkeletonFileFormat.h).
constexpr std::uint16_t kHeader = 0x1000;
constexpr std::uint16_t kMesh = 0x3000;
constexpr std::uint16_t kSubMesh = 0x4000;
constexpr std::uint16_t kSubMeshOperation = 0x4010;
constexpr std::uint16_t kSubMeshBoneAssignment = 0x4100;
constexpr std::uint16_t kSubMeshTextureAlias = 0x4200;
constexpr std::uint16_t kGeometry = 0x5000;
constexpr std::uint16_t kVertexDeclaration = 0x5100;
constexpr std::uint16_t kVertexElement = 0x5110;
constexpr std::uint16_t kVertexBuffer = 0x5200;
constexpr std::uint16_t kVertexBufferData = 0x5210;
constexpr std::uint16_t kSkeletonLink = 0x6000;
constexpr std::uint16_t kMeshBoneAssignment = 0x7000;
constexpr std::uint16_t kBounds = 0x9000;
// Mesh chunks skipped by their length: LOD levels, sub-mesh name table, edge lists, poses,
// vertex animations, extremes.
const std::set<std::uint16_t> kSkippedMeshChunks = {0x8000, 0xA000, 0xB000,
                                                    0xC000, 0xD000, 0xE000};

constexpr std::uint16_t kSkeletonBlendMode = 0x1010;
constexpr std::uint16_t kBone = 0x2000;
constexpr std::uint16_t kBoneParent = 0x3000;
constexpr std::uint16_t kAnimation = 0x4000;
constexpr std::uint16_t kAnimationBaseInfo = 0x4010;
constexpr std::uint16_t kAnimationTrack = 0x4100;
constexpr std::uint16_t kKeyframe = 0x4110;
constexpr std::uint16_t kAnimationLink = 0x5000;

constexpr std::size_t kChunkHeader = 6;

std::string hex(std::uint16_t id) {
  static const char* digits = "0123456789abcdef";
  std::string s = "0x";
  for (int shift = 12; shift >= 0; shift -= 4) s += digits[(id >> shift) & 0xF];
  return s;
}

/// A sequential reader over a ByteReader, as OGRE's serialisers read their stream.
class Cursor {
 public:
  Cursor(std::string_view data, const std::string& source)
      : reader_(data, source, ByteReader::Endian::kLittle) {}

  bool at_end() const { return pos_ >= reader_.size(); }
  std::size_t pos() const { return pos_; }
  std::size_t size() const { return reader_.size(); }
  const ByteReader& reader() const { return reader_; }

  std::uint16_t u16(const std::string& what) {
    const auto v = reader_.u16(pos_, what);
    pos_ += 2;
    return v;
  }
  std::uint32_t u32(const std::string& what) {
    const auto v = reader_.u32(pos_, what);
    pos_ += 4;
    return v;
  }
  double f32(const std::string& what) {
    const float v = reader_.f32(pos_, what);
    pos_ += 4;
    return v;
  }
  bool boolean(const std::string& what) {
    const bool v = reader_.u8(pos_, what) != 0;
    pos_ += 1;
    return v;
  }
  Eigen::Vector3d vec3(const std::string& what) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = f32(what);
    return v;
  }
  /// OGRE's file order x, y, z, w.
  Eigen::Quaterniond quat(const std::string& what) {
    const double x = f32(what), y = f32(what), z = f32(what), w = f32(what);
    return Eigen::Quaterniond(w, x, y, z);
  }
  /// A string ending at '\n' (OGRE's Serializer::readString); the newline is consumed.
  std::string line(const std::string& what) {
    const std::string_view rest = reader_.bytes(pos_, reader_.size() - pos_, what);
    const std::size_t end = rest.find('\n');
    if (end == std::string_view::npos) {
      reader_.fail(pos_, what, "string without its terminating newline (truncated or corrupt)");
    }
    pos_ += end + 1;
    return std::string(rest.substr(0, end));
  }
  void skip(std::size_t count, const std::string& what) {
    reader_.require(pos_, count, what);
    pos_ += count;
  }

  struct Chunk {
    std::uint16_t id = 0;
    std::uint32_t length = 0;
    std::size_t start = 0;  ///< offset of the chunk header
    std::string what() const { return "chunk " + hex(id); }
    std::size_t end() const { return start + length; }
  };
  /// How a chunk's length is used: to skip the chunk or to size its contents (kInside: it must
  /// end inside the file), or not at all because the contents are read item by item to their
  /// end (kSequential: only `length` ≥ 6 is checked; skip_rest() checks the end if it is used).
  enum class Extent { kInside, kSequential };

  /// Reads a chunk header; OGRE's check: the length covers at least the header and, for a
  /// chunk whose length is used, ends inside the file.
  Chunk chunk(const std::string& context, Extent extent = Extent::kInside) {
    Chunk c;
    c.start = pos_;
    c.id = u16(context + ": chunk id");
    c.length = u32(context + ": chunk " + hex(c.id) + " length");
    if (c.length < kChunkHeader) {
      reader_.fail(c.start, context + ": chunk " + hex(c.id),
                   "corrupt chunk length " + std::to_string(c.length) + " (below the 6-byte header)");
    }
    if (extent == Extent::kInside) require_inside(c, context + ": chunk " + hex(c.id));
    return c;
  }
  /// The id of the next chunk without consuming it, or nothing at the end of the data.
  std::optional<std::uint16_t> peek() const {
    if (pos_ + 2 > reader_.size()) return std::nullopt;
    return reader_.u16(pos_, "chunk id");
  }
  void skip_rest(const Chunk& c) {
    require_inside(c, c.what());
    if (c.end() < pos_) reader_.fail(c.start, c.what(), "chunk ends before its contents");
    pos_ = c.end();
  }
  void require_inside(const Chunk& c, const std::string& what) const {
    if (c.start + c.length > reader_.size()) {
      reader_.fail(c.start, what,
                   "corrupt chunk length " + std::to_string(c.length) +
                       " (runs past the end: the file has " + std::to_string(reader_.size()) +
                       " bytes; truncated, or miscounted by its exporter)");
    }
  }
  [[noreturn]] void fail(std::size_t offset, const std::string& what,
                         const std::string& message) const {
    reader_.fail(offset, what, message);
  }

 private:
  ByteReader reader_;
  std::size_t pos_ = 0;
};

std::string read_header(Cursor& in, const std::set<std::string>& versions, const char* kind) {
  const std::uint16_t id = in.u16("file header id");
  if (id != kHeader) {
    in.fail(0, "file header", std::string("not an OGRE binary ") + kind + " (header id " +
                                  hex(id) + ", expected 0x1000)");
  }
  const std::string version = in.line("file header version");
  if (versions.count(version) == 0) {
    std::string known;
    for (const auto& v : versions) known += (known.empty() ? "" : ", ") + v;
    in.fail(2, "file header version",
            "unsupported version '" + version.substr(0, 64) + "' (read: " + known + ")");
  }
  return version;
}

/// Vertex positions of one M_GEOMETRY chunk (its header already read).
Eigen::MatrixXd read_geometry(Cursor& in, const std::string& where) {
  const std::size_t start = in.pos();
  const std::uint32_t count = in.u32(where + ": vertex count");
  if (count > in.size()) in.fail(start, where, "vertex count " + std::to_string(count) + " exceeds the file size");
  struct Element {
    int source, type, semantic, offset;
  };
  std::vector<Element> elements;
  struct Buffer {
    int vertex_size;
    std::size_t data;
  };
  std::map<int, Buffer> buffers;
  while (auto id = in.peek()) {
    if (*id == kVertexDeclaration) {
      in.chunk(where);
      while (in.peek() == kVertexElement) {
        const auto c = in.chunk(where + ": vertex declaration");
        const std::string w = where + ": vertex element " + std::to_string(elements.size());
        Element e;
        e.source = in.u16(w);
        e.type = in.u16(w);
        e.semantic = in.u16(w);
        e.offset = in.u16(w);
        in.u16(w);  // index (of texture coordinates, colours)
        elements.push_back(e);
        (void)c;
      }
    } else if (*id == kVertexBuffer) {
      const auto c = in.chunk(where);
      const std::string w = where + ": vertex buffer at byte " + std::to_string(c.start);
      const int bind = in.u16(w + " bind index");
      const int vertex_size = in.u16(w + " vertex size");
      const auto data = in.chunk(w);
      if (data.id != kVertexBufferData) {
        in.fail(data.start, w, "expected the buffer data chunk 0x5210, found " + hex(data.id));
      }
      if (buffers.count(bind)) in.fail(c.start, w, "bind index " + std::to_string(bind) + " bound twice");
      buffers[bind] = {vertex_size, in.pos()};
      in.skip(static_cast<std::size_t>(count) * static_cast<std::size_t>(vertex_size),
              w + " data (" + std::to_string(count) + " vertices of " +
                  std::to_string(vertex_size) + " bytes)");
    } else {
      break;
    }
  }
  constexpr int kPosition = 1, kFloat3 = 2, kFloat4 = 3;
  const auto pos = std::find_if(elements.begin(), elements.end(),
                                [](const Element& e) { return e.semantic == kPosition; });
  Eigen::MatrixXd V(count, 3);
  if (count == 0) return V;
  if (pos == elements.end()) in.fail(start, where, "no position element in the vertex declaration");
  if (pos->type != kFloat3 && pos->type != kFloat4) {
    throw geometry::GeometryError(in.reader().source() + ": " + where +
                                  ": position element of type " + std::to_string(pos->type) +
                                  " (only FLOAT3 and FLOAT4 are read)");
  }
  const auto buffer = buffers.find(pos->source);
  if (buffer == buffers.end()) {
    in.fail(start, where, "no vertex buffer bound to the positions' source " + std::to_string(pos->source));
  }
  if (pos->offset + 12 > buffer->second.vertex_size) {
    in.fail(start, where, "position offset " + std::to_string(pos->offset) +
                              " does not fit the vertex size " +
                              std::to_string(buffer->second.vertex_size));
  }
  for (std::uint32_t v = 0; v < count; ++v) {
    const std::size_t at = buffer->second.data +
                           static_cast<std::size_t>(v) * buffer->second.vertex_size + pos->offset;
    for (int k = 0; k < 3; ++k) {
      V(v, k) = in.reader().f32(at + 4 * k, where + ": vertex " + std::to_string(v) + " position");
    }
  }
  if (!V.allFinite()) {
    throw geometry::GeometryError(in.reader().source() + ": " + where + ": non-finite vertex position");
  }
  return V;
}

BoneAssignment read_assignment(Cursor& in, const std::string& what, int vertex_offset,
                               int block_size) {
  const std::size_t at = in.pos();
  BoneAssignment a;
  const std::uint32_t v = in.u32(what);
  a.bone = in.u16(what);
  a.weight = in.f32(what);
  if (v >= static_cast<std::uint32_t>(block_size)) {
    in.fail(at, what, "vertex " + std::to_string(v) + " out of range (the block has " +
                          std::to_string(block_size) + " vertices)");
  }
  if (!std::isfinite(a.weight) || a.weight < 0) {
    in.fail(at, what, "weight " + std::to_string(a.weight) + " is negative or not finite");
  }
  a.vertex = vertex_offset + static_cast<int>(v);
  return a;
}

void append_block(Eigen::MatrixXd& V, const Eigen::MatrixXd& block) {
  Eigen::MatrixXd out(V.rows() + block.rows(), 3);
  out << V, block;
  V.swap(out);
}

}  // namespace

OgreMesh parse_mesh(std::string_view data, const std::string& source) {
  Cursor in(data, source);
  OgreMesh mesh;
  mesh.V.resize(0, 3);
  mesh.version = read_header(in,
                             {"[MeshSerializer_v1.100]", "[MeshSerializer_v1.10]",
                              "[MeshSerializer_v1.8]", "[MeshSerializer_v1.41]",
                              "[MeshSerializer_v1.40]", "[MeshSerializer_v1.30]"},
                             "mesh");
  bool seen_mesh = false;
  int shared_offset = -1, shared_count = 0;
  std::vector<Eigen::Vector3i> faces;
  while (!in.at_end()) {
    // M_MESH is read item by item to its end (OGRE's readMesh, OpenClonk's ChunkMesh): its
    // length is never used, and OpenClonk's [MeshSerializer_v1.8] Clonk outfits store one that
    // ends a byte past the file.
    const auto top = in.chunk("top level", Cursor::Extent::kSequential);
    if (top.id != kMesh) {  // OGRE's importMesh reads only M_MESH
      in.skip_rest(top);
      continue;
    }
    if (seen_mesh) in.fail(top.start, top.what(), "a second mesh chunk");
    seen_mesh = true;
    in.boolean("mesh: skeletally animated flag");
    while (auto id = in.peek()) {
      if (*id == kGeometry) {
        const auto c = in.chunk("mesh");
        if (shared_offset >= 0) in.fail(c.start, "shared geometry", "a second shared vertex block");
        const Eigen::MatrixXd block = read_geometry(in, "shared geometry");
        shared_offset = static_cast<int>(mesh.V.rows());
        shared_count = static_cast<int>(block.rows());
        append_block(mesh.V, block);
      } else if (*id == kSubMesh) {
        const auto c = in.chunk("mesh");
        const int s = mesh.num_submeshes++;
        const std::string w = "sub-mesh " + std::to_string(s) + " (byte " + std::to_string(c.start) + ")";
        in.line(w + " material name");
        const bool shared = in.boolean(w + " shared-vertices flag");
        const std::uint32_t index_count = in.u32(w + " index count");
        const bool wide = in.boolean(w + " 32-bit index flag");
        const std::size_t index_bytes = static_cast<std::size_t>(index_count) * (wide ? 4 : 2);
        const std::size_t index_start = in.pos();
        in.skip(index_bytes, w + " indices (" + std::to_string(index_count) + ")");
        std::vector<std::uint32_t> indices(index_count);
        for (std::uint32_t i = 0; i < index_count; ++i) {
          indices[i] = wide ? in.reader().u32(index_start + 4 * i, w + " index")
                            : in.reader().u16(index_start + 2 * i, w + " index");
        }
        int offset = shared_offset, block = shared_count;
        if (shared) {
          if (shared_offset < 0) in.fail(c.start, w, "uses shared vertices, but the mesh has none before it");
        } else {
          const auto g = in.chunk(w);
          if (g.id != kGeometry) in.fail(g.start, w, "expected its geometry chunk 0x5000, found " + hex(g.id));
          const Eigen::MatrixXd own = read_geometry(in, w + " geometry");
          offset = static_cast<int>(mesh.V.rows());
          block = static_cast<int>(own.rows());
          append_block(mesh.V, own);
        }
        int operation = 4;  // OT_TRIANGLE_LIST when the chunk is absent
        while (auto sub = in.peek()) {
          if (*sub == kSubMeshOperation) {
            in.chunk(w);
            operation = in.u16(w + " operation type");
          } else if (*sub == kSubMeshBoneAssignment) {
            in.chunk(w);
            // A sub-mesh on shared vertices has its assignments on the mesh; OGRE adds any here
            // to the sub-mesh, which then indexes the shared block too.
            mesh.assignments.push_back(read_assignment(
                in, w + " bone assignment " + std::to_string(mesh.assignments.size()), offset, block));
          } else if (*sub == kSubMeshTextureAlias) {
            in.chunk(w);
            in.line(w + " texture alias name");
            in.line(w + " texture name");
          } else {
            break;
          }
        }
        for (std::uint32_t i = 0; i < index_count; ++i) {
          if (indices[i] >= static_cast<std::uint32_t>(block)) {
            throw geometry::GeometryError(source + ": " + w + ": index " + std::to_string(i) +
                                          " refers to vertex " + std::to_string(indices[i]) +
                                          ", but its vertex block has " + std::to_string(block));
          }
        }
        auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c2) {
          if (a == b || b == c2 || a == c2) {
            ++mesh.num_dropped_degenerate;
            return;
          }
          faces.emplace_back(offset + static_cast<int>(a), offset + static_cast<int>(b),
                             offset + static_cast<int>(c2));
        };
        const std::size_t n = indices.size();
        if (operation == 4) {  // list
          for (std::size_t i = 0; i + 2 < n; i += 3) add(indices[i], indices[i + 1], indices[i + 2]);
        } else if (operation == 5) {  // strip: alternate winding
          for (std::size_t i = 0; i + 2 < n; ++i) {
            if (i % 2 == 0) add(indices[i], indices[i + 1], indices[i + 2]);
            else add(indices[i + 1], indices[i], indices[i + 2]);
          }
        } else if (operation == 6) {  // fan
          for (std::size_t i = 1; i + 1 < n; ++i) add(indices[0], indices[i], indices[i + 1]);
        } else if (operation < 1 || operation > 6) {
          in.fail(c.start, w, "unknown operation type " + std::to_string(operation));
        }  // 1-3: points and lines, no triangle
      } else if (*id == kSkeletonLink) {
        in.chunk("mesh");
        mesh.skeleton_link = in.line("skeleton link");
      } else if (*id == kMeshBoneAssignment) {
        in.chunk("mesh");
        if (shared_offset < 0) in.fail(in.pos(), "mesh bone assignment", "the mesh has no shared vertices");
        mesh.assignments.push_back(read_assignment(
            in, "mesh bone assignment " + std::to_string(mesh.assignments.size()), shared_offset,
            shared_count));
      } else if (*id == kBounds || kSkippedMeshChunks.count(*id)) {
        in.skip_rest(in.chunk("mesh"));
      } else {
        break;  // OGRE stops reading the mesh at the first chunk it does not know
      }
    }
    if (!in.at_end()) {
      const auto id = in.peek();
      if (!id) in.fail(in.pos(), "mesh", "a truncated chunk header");
      if (*id != kMesh) in.fail(in.pos(), "mesh", "unknown chunk " + hex(*id));
    }
  }
  if (!seen_mesh) in.fail(0, "file", "no mesh chunk (0x3000)");
  mesh.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) mesh.F.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  return mesh;
}

OgreSkeleton parse_skeleton(std::string_view data, const std::string& source) {
  Cursor in(data, source);
  OgreSkeleton skel;
  skel.version = read_header(in, {"[Serializer_v1.10]", "[Serializer_v1.80]"}, "skeleton");
  std::vector<bool> has_parent;
  while (!in.at_end()) {
    const auto c = in.chunk("skeleton");
    if (c.id == kSkeletonBlendMode) {
      in.u16("blend mode");
    } else if (c.id == kBone) {
      const std::string w = "bone " + std::to_string(skel.bones.size()) + " (byte " + std::to_string(c.start) + ")";
      OgreBone b;
      b.name = in.line(w + " name");
      const int handle = in.u16(w + " handle");
      if (handle != static_cast<int>(skel.bones.size())) {
        in.fail(c.start, w, "handle " + std::to_string(handle) + " where " +
                                std::to_string(skel.bones.size()) + " was expected (handles must be contiguous)");
      }
      b.position = in.vec3(w + " position");
      b.orientation = in.quat(w + " orientation");
      // OGRE's test: the length (which never counts the name) exceeds the scale-less 36 bytes.
      if (c.length > kChunkHeader + 2 + 12 + 16) b.scale = in.vec3(w + " scale");
      if (!b.position.allFinite() || !b.orientation.coeffs().allFinite() || !b.scale.allFinite() ||
          b.orientation.norm() < 1e-6) {
        in.fail(c.start, w + " '" + b.name + "'", "non-finite or zero transform");
      }
      b.orientation.normalize();
      skel.bones.push_back(b);
      has_parent.push_back(false);
    } else if (c.id == kBoneParent) {
      const int child = in.u16("bone parent: child");
      const int parent = in.u16("bone parent: parent");
      const int n = static_cast<int>(skel.bones.size());
      if (child >= n || parent >= n || child == parent) {
        in.fail(c.start, "bone parent", "child " + std::to_string(child) + ", parent " +
                                            std::to_string(parent) + " with " + std::to_string(n) + " bones");
      }
      if (has_parent[child]) in.fail(c.start, "bone parent", "bone " + std::to_string(child) + " has two parents");
      has_parent[child] = true;
      skel.bones[child].parent = parent;
    } else if (c.id == kAnimation) {
      OgreAnimation a;
      const std::string w = "animation " + std::to_string(skel.animations.size()) + " (byte " + std::to_string(c.start) + ")";
      a.name = in.line(w + " name");
      a.length = in.f32(w + " length");
      if (in.peek() == kAnimationBaseInfo) {
        in.chunk(w);
        in.line(w + " base animation name");
        in.f32(w + " base keyframe time");
      }
      while (in.peek() == kAnimationTrack) {
        const auto t = in.chunk(w);
        OgreTrack track;
        const std::string tw = w + " '" + a.name + "' track " + std::to_string(a.tracks.size());
        track.bone = in.u16(tw + " bone");
        if (track.bone >= static_cast<int>(skel.bones.size())) {
          in.fail(t.start, tw, "bone handle " + std::to_string(track.bone) + " out of range");
        }
        while (in.peek() == kKeyframe) {
          const auto k = in.chunk(tw);
          const std::string kw = tw + " keyframe " + std::to_string(track.keys.size());
          OgreKeyframe key;
          key.time = in.f32(kw);
          key.rotation = in.quat(kw);
          key.translation = in.vec3(kw);
          if (k.length > kChunkHeader + 4 + 16 + 12) key.scale = in.vec3(kw);
          if (!std::isfinite(key.time) || !key.rotation.coeffs().allFinite() ||
              !key.translation.allFinite() || !key.scale.allFinite() || key.rotation.norm() < 1e-6) {
            in.fail(k.start, kw, "non-finite or zero transform");
          }
          key.rotation.normalize();
          track.keys.push_back(key);
        }
        a.tracks.push_back(std::move(track));
      }
      if (!std::isfinite(a.length) || a.length < 0) in.fail(c.start, w, "bad length");
      skel.animations.push_back(std::move(a));
    } else if (c.id == kAnimationLink) {
      skel.animation_links.push_back(in.line("animation link"));
      in.f32("animation link scale");
    } else {
      in.fail(c.start, "skeleton", "unknown chunk " + hex(c.id));
    }
  }
  if (skel.bones.empty()) in.fail(0, "skeleton", "no bones");
  // Parent chains must end at a root (no cycle).
  for (std::size_t b = 0; b < skel.bones.size(); ++b) {
    std::size_t steps = 0;
    for (int p = skel.bones[b].parent; p >= 0; p = skel.bones[p].parent) {
      if (++steps > skel.bones.size()) {
        in.fail(0, "skeleton", "bone '" + skel.bones[b].name + "' is in a parent cycle");
      }
    }
  }
  return skel;
}

namespace {

/// OGRE's Node: derived = parent.derived ∘ local with inherited orientation and scale.
void derive(const OgreSkeleton& s, const std::vector<Eigen::Vector3d>& pos,
            const std::vector<Eigen::Quaterniond>& rot, const std::vector<Eigen::Vector3d>& scale,
            BindPose& out) {
  const std::size_t n = s.bones.size();
  out.position.assign(n, Eigen::Vector3d::Zero());
  out.orientation.assign(n, Eigen::Quaterniond::Identity());
  out.scale.assign(n, Eigen::Vector3d::Ones());
  std::vector<bool> done(n, false);
  std::function<void(std::size_t)> visit = [&](std::size_t b) {
    if (done[b]) return;
    const int p = s.bones[b].parent;
    if (p < 0) {
      out.position[b] = pos[b];
      out.orientation[b] = rot[b];
      out.scale[b] = scale[b];
    } else {
      visit(static_cast<std::size_t>(p));
      out.orientation[b] = (out.orientation[p] * rot[b]).normalized();
      out.scale[b] = out.scale[p].cwiseProduct(scale[b]);
      out.position[b] = out.orientation[p] * out.scale[p].cwiseProduct(pos[b]) + out.position[p];
    }
    done[b] = true;
  };
  for (std::size_t b = 0; b < n; ++b) visit(b);
}

}  // namespace

BindPose derive_bind_pose(const OgreSkeleton& skeleton) {
  std::vector<Eigen::Vector3d> pos, scale;
  std::vector<Eigen::Quaterniond> rot;
  for (const auto& b : skeleton.bones) {
    pos.push_back(b.position);
    rot.push_back(b.orientation);
    scale.push_back(b.scale);
  }
  BindPose out;
  derive(skeleton, pos, rot, scale, out);
  return out;
}

BindPose sample_animation(const OgreSkeleton& skeleton, const OgreAnimation& animation,
                          double time) {
  std::vector<Eigen::Vector3d> pos, scale;
  std::vector<Eigen::Quaterniond> rot;
  for (const auto& b : skeleton.bones) {
    pos.push_back(b.position);
    rot.push_back(b.orientation);
    scale.push_back(b.scale);
  }
  for (const OgreTrack& track : animation.tracks) {
    if (track.keys.empty()) continue;
    const auto& keys = track.keys;
    OgreKeyframe k;
    if (time <= keys.front().time) {
      k = keys.front();
    } else if (time >= keys.back().time) {
      k = keys.back();
    } else {
      std::size_t i = 1;
      while (i < keys.size() && keys[i].time <= time) ++i;  // keys[i-1].time <= time < keys[i]
      const OgreKeyframe& a = keys[i - 1];
      const OgreKeyframe& b = keys[std::min(i, keys.size() - 1)];
      const double span = b.time - a.time;
      const double t = span > 0 ? (time - a.time) / span : 0.0;
      k.translation = a.translation + t * (b.translation - a.translation);
      k.scale = a.scale + t * (b.scale - a.scale);
      Eigen::Vector4d qb = b.rotation.coeffs();
      if (a.rotation.coeffs().dot(qb) < 0) qb = -qb;  // shortest path
      const Eigen::Vector4d q = a.rotation.coeffs() + t * (qb - a.rotation.coeffs());
      k.rotation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
    }
    // Bone::_applyAnimation: translate in parent space, rotate in local space, scale.
    pos[track.bone] += k.translation;
    rot[track.bone] = (rot[track.bone] * k.rotation).normalized();
    scale[track.bone] = scale[track.bone].cwiseProduct(k.scale);
  }
  BindPose out;
  derive(skeleton, pos, rot, scale, out);
  return out;
}

}  // namespace skinlab::datasets::ogre
