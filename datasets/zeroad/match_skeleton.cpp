#include "datasets/zeroad/match_skeleton.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>

namespace skinlab::datasets::zeroad {

namespace {

double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

double proximity(const Pmd& pmd, const std::vector<int>& parents, double scale) {
  const int nb = pmd.num_bones();
  std::vector<std::vector<int>> children(nb);
  for (int j = 0; j < nb; ++j)
    if (parents[j] >= 0) children[parents[j]].push_back(j);
  std::vector<double> d;
  d.reserve(pmd.positions.rows());
  for (Eigen::Index v = 0; v < pmd.positions.rows(); ++v) {
    int k_best = 0;
    for (int k = 1; k < 4; ++k)
      if (pmd.bone_weights(v, k) > pmd.bone_weights(v, k_best)) k_best = k;
    const int j = pmd.bone_indices(v, k_best);
    if (j < 0) continue;
    const Eigen::Vector3d p = pmd.positions.row(v).transpose();
    const Eigen::Vector3d a = pmd.bind[j].translation();
    double best = (p - a).norm();
    for (int c : children[j])
      best = std::min(best, segment_distance(p, a, pmd.bind[c].translation()));
    d.push_back(best / scale);
  }
  if (d.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

double rigid_fraction(const Pmd& pmd, const std::vector<int>& parents,
                      const std::vector<const Psa*>& clips, double scale) {
  // Only bones that deform the mesh: unweighted helpers (prop points, IK targets) may slide.
  std::vector<bool> weighted(pmd.num_bones(), false);
  for (Eigen::Index v = 0; v < pmd.bone_indices.rows(); ++v)
    for (int k = 0; k < 4; ++k)
      if (pmd.bone_indices(v, k) >= 0 && pmd.bone_weights(v, k) > 0)
        weighted[pmd.bone_indices(v, k)] = true;
  int joints = 0, consistent = 0;
  for (int j = 0; j < pmd.num_bones(); ++j) {
    const int p = parents[j];
    if (p < 0 || !weighted[j]) continue;
    const Eigen::Vector3d rest = (pmd.bind[p].inverse() * pmd.bind[j]).translation();
    double worst = 0;
    for (const Psa* clip : clips)
      for (const auto& frame : clip->frames)
        worst = std::max(worst, ((frame[p].inverse() * frame[j]).translation() - rest).norm());
    ++joints;
    if (worst <= kRigidTolerance * scale) ++consistent;
  }
  return joints == 0 ? 1.0 : static_cast<double>(consistent) / joints;
}

std::string fixed(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", x);
  return buf;
}

}  // namespace

SkeletonMatch match_skeleton(const Pmd& pmd, const std::vector<StandardSkeleton>& skeletons,
                             const std::vector<const Psa*>& all_clips) {
  SkeletonMatch m;
  const int nb = pmd.num_bones();
  std::vector<const Psa*> clips;
  for (const Psa* c : all_clips)
    if (c->num_bones == nb && !c->frames.empty()) clips.push_back(c);
  m.clips_checked = static_cast<int>(clips.size());

  const Eigen::Vector3d lo = pmd.positions.colwise().minCoeff(),
                        hi = pmd.positions.colwise().maxCoeff();
  const double scale = std::max((hi - lo).norm(), 1e-9);

  std::vector<int> distinct;
  for (int i = 0; i < static_cast<int>(skeletons.size()); ++i) {
    const auto& s = skeletons[i];
    if (static_cast<int>(s.names.size()) != nb) continue;
    bool seen = false;
    for (int k : distinct)
      seen = seen || (skeletons[k].names == s.names && skeletons[k].parents == s.parents);
    if (!seen) distinct.push_back(i);
  }
  m.candidates = static_cast<int>(distinct.size());
  if (distinct.empty()) {
    m.reason = "no standard skeleton has " + std::to_string(nb) + " bones";
    return m;
  }
  int best = -1;
  double best_rigid = -1, best_prox = 0;
  for (int i : distinct) {
    const double r = clips.empty() ? -1 : rigid_fraction(pmd, skeletons[i].parents, clips, scale);
    const double p = proximity(pmd, skeletons[i].parents, scale);
    if (best < 0 || r > best_rigid + 1e-12 || (r > best_rigid - 1e-12 && p < best_prox)) {
      best = i;
      best_rigid = r;
      best_prox = p;
    }
  }
  m.rigid_fraction = best_rigid;
  m.proximity = best_prox;
  const std::string which = "standard skeleton '" + skeletons[best].id + "' (" +
                            skeletons[best].file + ", best of " + std::to_string(m.candidates) +
                            " with " + std::to_string(nb) + " bones)";
  if (!clips.empty() && best_rigid < kMinRigidFraction) {
    m.reason = which + " fails the clip check: only " + fixed(best_rigid) +
               " of its bones keep their bind-pose offset over " + std::to_string(clips.size()) +
               " clips (needs " + fixed(kMinRigidFraction) + ")";
  } else if (best_prox > kMaxProximity) {
    m.reason = which + " fails the bind-pose check: median vertex-to-bone distance " +
               fixed(best_prox) + " of the mesh size (at most " + fixed(kMaxProximity) + ")";
  } else {
    m.index = best;
  }
  return m;
}

}  // namespace skinlab::datasets::zeroad
