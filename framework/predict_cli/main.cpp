/// \file
/// `skinlab-predict`: skin weights with a bundled model and no libtorch (issue 24). The same
/// inputs, options and outputs as `skinlab predict` (infer/predict_command.hpp, shared), the
/// same preprocessing, candidate selection, pruning and export (infer/prediction.hpp,
/// infer/outputs.hpp), and HeterSkinNet's forward pass in Eigen (infer/network.hpp) on the
/// bundle's parameters.h5 (infer/parameters.hpp, docs/parameters.md):
///
///     skinlab-predict hero.fbx --out hero.glb
///     skinlab-predict a.fbx b.glb chars/ @more.txt --out-dir skinned --format glb
///
/// It links neither libtorch nor anything libtorch pulls in (the `predict_cli_links_no_torch`
/// test checks the binary), so it starts in a fraction of the time. `--compare-to-input`,
/// `--render` and `--error-map` need the metrics and renderer of the libtorch program: use
/// `skinlab predict` for them. Like `skinlab`, every error is one line on stderr,
/// "skinlab-predict: error: ...", with exit status 1 and no partial output file.

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>

#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "framework/core/environment.hpp"
#include "framework/core/error.hpp"
#include "framework/core/interrupt.hpp"
#include "framework/core/logging.hpp"
#include "framework/core/registry.hpp"
#include "framework/infer/eigen_predictor.hpp"
#include "framework/infer/predict_command.hpp"

int main(int argc, char** argv) {
  skinlab::install_interrupt_cleanup("skinlab-predict");
  skinlab::keep_freed_memory();
  CLI::App app{"skinlab-predict: skin weights for characters with a bundled HeterSkinNet, "
               "without libtorch (glTF, rig text, HDF5): one input with --out FILE, or many "
               "with --out-dir DIR"};
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  int threads = 0;
  app.add_option("--threads", threads, "threads; 0 = every hardware thread")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  skinlab::infer::PredictArgs args;
  skinlab::infer::add_predict_options(app, args);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    skinlab::logging::init(log_level);
    skinlab::verify_registries();
    const std::size_t parallelism =
        threads > 0 ? static_cast<std::size_t>(threads)
                    : std::max<std::size_t>(1, std::thread::hardware_concurrency());
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, parallelism);
    skinlab::infer::PredictHooks hooks;
    hooks.load = [](const std::filesystem::path& dir, const skinlab::infer::PredictArgs&) {
      return std::make_unique<skinlab::infer::EigenPredictor>(
          skinlab::infer::EigenPredictor::load(dir));
    };
    return skinlab::infer::run_predict(args, hooks);
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::cerr << "skinlab-predict: error: " << e.what() << "\n";
    return 1;
  }
}
