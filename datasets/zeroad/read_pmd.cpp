#include "datasets/zeroad/read_pmd.hpp"

#include <cmath>

#include "datasets/zeroad/byte_reader.hpp"

namespace skinlab::datasets::zeroad {

namespace {

double finite(ByteReader& r, const std::string& what) {
  const std::size_t at = r.offset();
  const float f = r.f32(what);
  if (!std::isfinite(f)) r.fail_at(at, what + " is not finite");
  return f;
}

Eigen::Isometry3d rigid(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = q.normalized().toRotationMatrix();
  m.translation() = t;
  return m;
}

Eigen::Quaterniond quaternion(ByteReader& r, const std::string& what) {
  const std::size_t at = r.offset();
  const double x = finite(r, what), y = finite(r, what), z = finite(r, what), w = finite(r, what);
  Eigen::Quaterniond q(w, x, y, z);
  if (q.norm() < 1e-6) r.fail_at(at, what + " is a zero quaternion");
  return q;
}

}  // namespace

Pmd read_pmd(const std::string& bytes, const std::string& source) {
  ByteReader r(bytes, source);
  Pmd pmd;
  const std::uint32_t version = r.header("PSMD");
  if (version < 1 || version > 4) {
    r.fail_at(4, "unsupported PMD version " + std::to_string(version) + " (1 to 4 are known)");
  }
  pmd.version = static_cast<int>(version);

  const std::uint32_t nv = r.u32("the vertex count");
  const std::uint32_t nuv = version >= 4 ? r.u32("the UV set count") : 1;
  if (nuv > 8) r.fail("implausible UV set count " + std::to_string(nuv));
  r.need_elements(nv, 24 + 8 * nuv + 20, "vertex");
  pmd.positions.resize(nv, 3);
  pmd.normals.resize(nv, 3);
  pmd.uvs.resize(nv, 2 * nuv);
  pmd.bone_indices.resize(nv, 4);
  pmd.bone_weights.resize(nv, 4);
  for (std::uint32_t v = 0; v < nv; ++v) {
    const std::string at = "vertex " + std::to_string(v);
    for (int k = 0; k < 3; ++k) pmd.positions(v, k) = finite(r, at + " position");
    for (int k = 0; k < 3; ++k) pmd.normals(v, k) = finite(r, at + " normal");
    for (std::uint32_t k = 0; k < 2 * nuv; ++k) pmd.uvs(v, k) = finite(r, at + " uv");
    for (int k = 0; k < 4; ++k) {
      const std::uint8_t b = r.u8(at + " bone index");
      pmd.bone_indices(v, k) = b == 0xFF ? -1 : b;
    }
    for (int k = 0; k < 4; ++k) {
      const double w = finite(r, at + " bone weight");
      pmd.bone_weights(v, k) = pmd.bone_indices(v, k) < 0 ? 0.0 : w;
    }
  }

  const std::uint32_t nf = r.u32("the face count");
  r.need_elements(nf, 6, "face");
  pmd.faces.resize(nf, 3);
  for (std::uint32_t f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const std::size_t at = r.offset();
      const std::uint16_t i = r.u16("face " + std::to_string(f));
      if (i >= nv) {
        r.fail_at(at, "face " + std::to_string(f) + " vertex index " + std::to_string(i) +
                          " out of range (" + std::to_string(nv) + " vertices)");
      }
      pmd.faces(f, k) = i;
    }
  }

  const std::size_t bones_at = r.offset();
  const std::uint32_t nb = r.u32("the bone count");
  if (nb > 255) r.fail_at(bones_at, "bone count " + std::to_string(nb) + " exceeds 255");
  r.need_elements(nb, 28, "bone");
  for (std::uint32_t b = 0; b < nb; ++b) {
    const std::string at = "bone " + std::to_string(b);
    Eigen::Vector3d t;
    for (int k = 0; k < 3; ++k) t[k] = finite(r, at + " translation");
    pmd.bind.push_back(rigid(t, quaternion(r, at + " rotation")));
  }
  // Influences name bones by index: check them against the count now that it is known.
  for (std::uint32_t v = 0; v < nv; ++v) {
    for (int k = 0; k < 4; ++k) {
      const int b = pmd.bone_indices(v, k);
      if (b >= static_cast<int>(nb)) {
        // offset of this vertex's bone byte: after the header, #V (and #UV) fields
        const std::size_t stride = 24 + 8 * nuv + 20;
        const std::size_t at = 12 + (version >= 4 ? 8 : 4) + v * stride + 24 + 8 * nuv + k;
        r.fail_at(at, "vertex " + std::to_string(v) + " bone index " + std::to_string(b) +
                          " out of range (" + std::to_string(nb) + " bones)");
      }
    }
  }

  if (version >= 2) {
    const std::uint32_t np = r.u32("the prop point count");
    for (std::uint32_t p = 0; p < np; ++p) {
      const std::string at = "prop point " + std::to_string(p);
      PmdPropPoint prop;
      prop.name = r.str(at + " name");
      for (int k = 0; k < 3; ++k) prop.position[k] = finite(r, at + " position");
      prop.rotation = quaternion(r, at + " rotation");
      const std::size_t bone_at = r.offset();
      const std::uint8_t b = r.u8(at + " bone");
      prop.bone = b == 0xFF ? -1 : b;
      if (prop.bone >= static_cast<int>(nb)) {
        r.fail_at(bone_at, at + " '" + prop.name + "' bone " + std::to_string(prop.bone) +
                               " out of range (" + std::to_string(nb) + " bones)");
      }
      pmd.props.push_back(std::move(prop));
    }
  }
  if (version <= 2) {
    // Older files have no "root" prop point; the engine adds it.
    pmd.props.push_back({"root", Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity(), -1});
    // ... and store vertices relative to the bind pose: skin them into object space.
    if (nb > 0) {
      for (std::uint32_t v = 0; v < nv; ++v) {
        const Eigen::Vector3d p0 = pmd.positions.row(v).transpose();
        const Eigen::Vector3d n0 = pmd.normals.row(v).transpose();
        Eigen::Vector3d p = Eigen::Vector3d::Zero(), n = Eigen::Vector3d::Zero();
        for (int k = 0; k < 4; ++k) {
          const int b = pmd.bone_indices(v, k);
          if (b < 0) break;
          p += pmd.bone_weights(v, k) * (pmd.bind[b] * p0);
          n += pmd.bone_weights(v, k) * (pmd.bind[b].linear() * n0);
        }
        pmd.positions.row(v) = p.transpose();
        if (n.norm() > 0) pmd.normals.row(v) = n.normalized().transpose();
      }
    }
  }
  r.finish();
  return pmd;
}

}  // namespace skinlab::datasets::zeroad
