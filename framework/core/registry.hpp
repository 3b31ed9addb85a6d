#pragma once
/// \file
/// One registry template and one accessor per plug-in category.
///
/// A plug-in registers itself at the bottom of its own `.cpp`:
///
///     SKINLAB_REGISTER(loss, kl, KlLoss);
///
/// which makes `type: kl` in a `losses:` entry construct `KlLoss(KlLoss::Options::from(node))`.
/// The key, the file stem and the YAML `type:` are the same snake_case string. Plug-ins are
/// compiled into an OBJECT library so the linker keeps every registrar; a test asserts the exact
/// key list of every category.

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "framework/core/config.hpp"
#include "framework/core/error.hpp"

namespace skinlab {

/// What `skinlab info` and error messages need from any registry, whatever its interface type.
class RegistryBase {
 public:
  virtual ~RegistryBase() = default;
  /// Category name as used in messages and `skinlab info` ("loss", "distance", ...).
  virtual const std::string& name() const = 0;
  /// Registered keys, sorted.
  virtual std::vector<std::string> keys() const = 0;
  /// Throws the first registration error (duplicate key) recorded at static-initialisation time.
  virtual void check() const = 0;
};

/// Maps a snake_case key to a factory that builds a `T` from its config node. `T` may be an
/// incomplete type where only keys are listed; it must be complete where `create` is called.
template <class T>
class Registry final : public RegistryBase {
 public:
  using Factory = std::function<std::shared_ptr<T>(const config::Node&)>;

  explicit Registry(std::string name) : name_(std::move(name)) {}
  Registry(const Registry&) = delete;
  Registry& operator=(const Registry&) = delete;

  /// Adds `key`. A duplicate key throws RegistryError naming both registration sites.
  void add(const std::string& key, Factory factory, std::string site = "") {
    if (key.empty()) throw RegistryError(name_ + " registry: empty key registered at " + site);
    auto [it, inserted] = entries_.try_emplace(key, Entry{std::move(factory), site});
    if (!inserted) {
      throw RegistryError(name_ + " registry: duplicate key '" + key + "' registered at " +
                          site + " (first registered at " + it->second.site + ")");
    }
  }

  bool contains(std::string_view key) const { return entries_.count(std::string(key)) > 0; }

  std::vector<std::string> keys() const override {
    std::vector<std::string> out;
    for (const auto& [key, entry] : entries_) out.push_back(key);
    return out;  // std::map keeps them sorted
  }

  const std::string& name() const override { return name_; }

  /// Builds the plug-in named by `node.type` with the rest of `node` as its options.
  std::shared_ptr<T> create(const config::Node& node) const {
    return create(node.required_type(name_), node);
  }

  /// Builds plug-in `key` from `options`. An unknown key throws RegistryError listing every
  /// known key, prefixed by the config location of `options` when it has one.
  std::shared_ptr<T> create(const std::string& key, const config::Node& options) const {
    check();
    auto it = entries_.find(key);
    if (it == entries_.end()) throw RegistryError(options.where() + unknown_key_message(key));
    return it->second.factory(options);
  }

  std::string unknown_key_message(const std::string& key) const {
    std::string known;
    for (const auto& k : keys()) known += (known.empty() ? "" : ", ") + k;
    return "unknown " + name_ + " type '" + key + "'; known " + name_ +
           " types: " + (known.empty() ? "(none registered)" : known);
  }

  /// Records a registration error for `check()`; used by Registrar, which runs before main().
  void record_error(std::string message) { errors_.push_back(std::move(message)); }

  void check() const override {
    if (!errors_.empty()) throw RegistryError(errors_.front());
  }

 private:
  struct Entry {
    Factory factory;
    std::string site;
  };
  std::string name_;
  std::map<std::string, Entry> entries_;
  std::vector<std::string> errors_;
};

/// Registers at static-initialisation time. Exceptions cannot leave a static initialiser
/// usefully, so a duplicate is recorded in the registry and raised by `check()`, which
/// `verify_registries()` (called first thing by the CLI) and every `create` run.
template <class T>
class Registrar {
 public:
  Registrar(Registry<T>& registry, const std::string& key, typename Registry<T>::Factory factory,
            const char* file, int line) {
    try {
      registry.add(key, std::move(factory), std::string(file) + ":" + std::to_string(line));
    } catch (const RegistryError& e) {
      registry.record_error(e.what());
    }
  }
};

// ---- categories -------------------------------------------------------------------------------
// Interfaces live with their category (framework/<category>/); here they are only declared, so
// core does not depend on geometry or libtorch headers.
namespace distances { class Distance; }
namespace graph { class GraphOp; }
namespace models { class Model; class CorrectiveModel; }
namespace losses { class Loss; }
namespace eval { class Metric; }
namespace datasets { class DatasetBuilder; }
namespace binders { class Binder; }
namespace task { class Task; }

/// `distance`: vertex–bone distances (Euclidean, HollowDist, volumetric geodesic).
Registry<distances::Distance>& distance_registry();
/// `graph_op`: graph convolutions on the heterogeneous mesh/skeleton graph.
Registry<graph::GraphOp>& graph_op_registry();
/// `model`: complete skinning networks (HeterSkinNet and the baselines).
Registry<models::Model>& model_registry();
/// `corrective_model`: networks predicting a per-vertex corrective displacement over linear
/// blend skinning (DenseGATs, experiments/densegats).
Registry<models::CorrectiveModel>& corrective_model_registry();
/// `loss`: training losses combined by weight.
Registry<losses::Loss>& loss_registry();
/// `metric`: evaluation metrics.
Registry<eval::Metric>& metric_registry();
/// `dataset`: builders turning a raw source into the HDF5 dataset.
Registry<datasets::DatasetBuilder>& dataset_registry();
/// `binder`: skinning weights from geometry alone, not learned (GeoVoxel, bone heat).
Registry<binders::Binder>& binder_registry();
Registry<task::Task>& task_registry();

/// Every category, in the order above.
std::vector<const RegistryBase*> all_registries();

/// Throws the first registration error of any category. Call once at start-up.
void verify_registries();

}  // namespace skinlab

#define SKINLAB_CONCAT_INNER(a, b) a##b
#define SKINLAB_CONCAT(a, b) SKINLAB_CONCAT_INNER(a, b)

/// Registers `Class` under `key` in the `category` registry. `Class` has a nested `Options`
/// struct with `static Options from(const config::Node&)` and a constructor taking `Options`.
#define SKINLAB_REGISTER(category, key, Class)                                                 \
  static const auto SKINLAB_CONCAT(skinlab_registrar_, __COUNTER__) = ::skinlab::Registrar(       \
      ::skinlab::category##_registry(), #key,                                                  \
      [](const ::skinlab::config::Node& node) {                                                \
        return std::make_shared<Class>(Class::Options::from(node));                            \
      },                                                                                       \
      __FILE__, __LINE__)
