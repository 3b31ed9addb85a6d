#include "datasets/zeroad/read_psa.hpp"

#include <cmath>

#include "datasets/zeroad/byte_reader.hpp"

namespace skinlab::datasets::zeroad {

Psa read_psa(const std::string& bytes, const std::string& source) {
  ByteReader r(bytes, source);
  const std::uint32_t version = r.header("PSSA");
  if (version != 1)
    r.fail_at(4, "unsupported PSA version " + std::to_string(version) + " (1 is known)");
  Psa psa;
  psa.name = r.str("the animation name");
  const std::size_t time_at = r.offset();
  psa.frame_time_ms = r.f32("the frame time");
  if (!(psa.frame_time_ms > 0) || !std::isfinite(psa.frame_time_ms)) {
    r.fail_at(time_at, "frame time " + std::to_string(psa.frame_time_ms) + " is not positive");
  }
  const std::uint32_t nb = r.u32("the bone count");
  const std::uint32_t nf = r.u32("the frame count");
  if (nb > 255) r.fail("bone count " + std::to_string(nb) + " exceeds 255");
  // Frames of no bones take no bytes: their count would be bounded by nothing.
  if (nb == 0 && nf > 0) r.fail(std::to_string(nf) + " frames of 0 bones");
  r.need_elements(nf, static_cast<std::size_t>(nb) * 28, "frame");
  psa.num_bones = static_cast<int>(nb);
  psa.frames.assign(nf, std::vector<Eigen::Isometry3d>(nb, Eigen::Isometry3d::Identity()));
  for (std::uint32_t f = 0; f < nf; ++f) {
    for (std::uint32_t b = 0; b < nb; ++b) {
      const std::size_t at = r.offset();
      double v[7];
      for (double& x : v) x = r.f32("frame " + std::to_string(f) + " bone " + std::to_string(b));
      const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
      bool ok = q.norm() > 1e-6;
      for (double x : v) ok = ok && std::isfinite(x);
      if (!ok) {
        r.fail_at(at, "frame " + std::to_string(f) + " bone " + std::to_string(b) +
                          ": non-finite key or zero quaternion");
      }
      Eigen::Isometry3d& m = psa.frames[f][b];
      m.linear() = q.normalized().toRotationMatrix();
      m.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    }
  }
  r.finish();
  return psa;
}

}  // namespace skinlab::datasets::zeroad
