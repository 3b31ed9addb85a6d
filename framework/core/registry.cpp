#include "framework/core/registry.hpp"

namespace skinlab {

Registry<distances::Distance>& distance_registry() {
  static Registry<distances::Distance> registry("distance");
  return registry;
}
Registry<graph::GraphOp>& graph_op_registry() {
  static Registry<graph::GraphOp> registry("graph_op");
  return registry;
}
Registry<models::Model>& model_registry() {
  static Registry<models::Model> registry("model");
  return registry;
}
Registry<models::CorrectiveModel>& corrective_model_registry() {
  static Registry<models::CorrectiveModel> registry("corrective_model");
  return registry;
}
Registry<losses::Loss>& loss_registry() {
  static Registry<losses::Loss> registry("loss");
  return registry;
}
Registry<eval::Metric>& metric_registry() {
  static Registry<eval::Metric> registry("metric");
  return registry;
}
Registry<datasets::DatasetBuilder>& dataset_registry() {
  static Registry<datasets::DatasetBuilder> registry("dataset");
  return registry;
}

Registry<binders::Binder>& binder_registry() {
  static Registry<binders::Binder> registry("binder");
  return registry;
}

Registry<task::Task>& task_registry() {
  static Registry<task::Task> registry("task");
  return registry;
}

std::vector<const RegistryBase*> all_registries() {
  return {&distance_registry(), &graph_op_registry(), &model_registry(),
          &corrective_model_registry(), &loss_registry(), &metric_registry(),
          &dataset_registry(), &binder_registry(), &task_registry()};
}

void verify_registries() {
  for (const auto* registry : all_registries()) registry->check();
}

}  // namespace skinlab
