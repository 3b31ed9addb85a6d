#pragma once
/// \file
/// Interface of the `loss` registry and the weighted sum of losses a config lists.
///
///     losses:
///       - {type: kl, weight: 1.0}
///       - {type: laplacian_smoothing, weight: 0.4}   # λ_S of HeterSkinNet Eq. 6
///
/// Every loss is a mean over rows (vertices), so the ratio of two weights means the same thing
/// as in a paper that writes both terms as sums over the same vertices, while the magnitude does
/// not depend on the mesh size.

#include <torch/torch.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "framework/core/config.hpp"

namespace skinlab::losses {

/// What a loss may look at. Absent tensors are undefined (`!t.defined()`).
struct LossInputs {
  torch::Tensor pred{};     ///< #V×C prediction (for weights: rows are distributions)
  torch::Tensor target{};   ///< #V×C ground truth, same shape as `pred`
  torch::Tensor laplacian{};  ///< #V×#V mesh Laplacian (sparse COO or dense), for smoothing terms
  /// Per prior the character was prepared with (e.g. "bone_heat"): that classical method's
  /// weights laid out as `pred` (#V×C, zero outside the candidates), for terms that anchor the
  /// prediction to it (prior_kl.hpp)
  std::map<std::string, torch::Tensor> priors{};
};

/// Keys every `losses:` entry may carry besides the loss's own options.
inline const std::vector<std::string> kReservedKeys = {"type", "weight"};

class Loss {
 public:
  virtual ~Loss() = default;
  /// A 0-dim tensor, differentiable with respect to `in.pred`.
  virtual torch::Tensor operator()(const LossInputs& in) const = 0;
  /// The names of the priors this loss reads from `LossInputs::priors`; the trainer lays out
  /// only those (train::loss_inputs), so a loss that reads one must name it here.
  virtual std::vector<std::string> priors() const { return {}; }
};

/// Throws std::invalid_argument (via TORCH_CHECK) unless `pred` and `target` are defined,
/// 2-D floating tensors of the same shape.
void check_pred_target(const LossInputs& in, const char* loss_name);

/// Σ_i weight_i · loss_i over a `losses:` list.
class LossSum {
 public:
  /// Builds every entry of a `losses:` list through the registry. Weights default to 1 and must
  /// be finite and ≥ 0; an empty list is an error.
  static LossSum from(const config::Node& list);

  /// Total loss. When `parts` is given it receives each term's (unweighted) value by type; a
  /// type listed twice is reported as `type`, `type#2`, ...
  torch::Tensor operator()(const LossInputs& in, std::map<std::string, double>* parts = nullptr) const;

  /// The priors any term reads (Loss::priors), each once, sorted; collected by `from`.
  const std::vector<std::string>& priors() const { return priors_; }

  struct Term {
    std::string name;
    double weight;
    std::shared_ptr<Loss> loss;
  };
  const std::vector<Term>& terms() const { return terms_; }

 private:
  std::vector<Term> terms_;
  std::vector<std::string> priors_;
};

}  // namespace skinlab::losses
