#include "framework/train/checkpoint.hpp"

#include <fmt/format.h>
#include <zip.h>

#include <cctype>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <vector>

#include "framework/core/atomic_file.hpp"
#include "framework/core/error.hpp"

namespace skinlab::train {

namespace {

/// Reads every entry of the zip archive `path` through libzip, which checks the central
/// directory against the local headers (ZIP_CHECKCONS) and each entry's CRC-32, and throws
/// IoError naming the file and the entry at the first damage. A checkpoint is a zip archive
/// that libtorch trusts: a damaged one reaches its unpickler (and could crash it), so no byte
/// goes to libtorch before this check.
void check_zip_archive(const std::filesystem::path& path) {
  const std::string where = path.string() + ": not a readable checkpoint (damaged zip archive";
  int code = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &code);
  if (archive == nullptr) {
    zip_error_t error;
    zip_error_init_with_code(&error, code);
    const std::string message = zip_error_strerror(&error);
    zip_error_fini(&error);
    throw IoError(where + ": " + message + ")");
  }
  const std::unique_ptr<zip_t, void (*)(zip_t*)> guard(archive, zip_discard);
  const zip_int64_t entries = zip_get_num_entries(archive, 0);
  std::vector<char> buffer(1 << 16);
  for (zip_int64_t i = 0; i < entries; ++i) {
    const char* name = zip_get_name(archive, static_cast<zip_uint64_t>(i), 0);
    const std::string entry = name != nullptr ? name : "#" + std::to_string(i);
    zip_file_t* file = zip_fopen_index(archive, static_cast<zip_uint64_t>(i), 0);
    if (file == nullptr) {
      throw IoError(where + ": entry '" + entry + "': " + zip_strerror(archive) + ")");
    }
    zip_int64_t got = 0;
    while ((got = zip_fread(file, buffer.data(), buffer.size())) > 0) {
    }
    const std::string message = got < 0 ? zip_file_strerror(file) : "";
    zip_fclose(file);
    if (got < 0) throw IoError(where + ": entry '" + entry + "': " + message + ")");
  }
}

}  // namespace

std::filesystem::path checkpoint_file(const std::filesystem::path& run_dir,
                                      const std::string& which) {
  if (which != "best" && which != "last") {
    throw Error("unknown checkpoint '" + which + "'; choose best or last");
  }
  return run_dir / (which + ".pt");
}

std::filesystem::path existing_checkpoint(const std::filesystem::path& run_dir,
                                          const std::string& which) {
  std::filesystem::path file = checkpoint_file(run_dir, which);
  if (!std::filesystem::exists(file)) {
    throw IoError(file.string() + ": no checkpoint '" + which +
                  "' in this run (a run writes best.pt and last.pt after its first epoch)");
  }
  return file;
}

namespace fs = std::filesystem;

namespace {

std::string shape_text(const torch::Tensor& t) {
  std::string out = "[";
  for (std::int64_t d = 0; d < t.dim(); ++d) out += (d ? ", " : "") + std::to_string(t.size(d));
  return out + "]";
}

/// name → shape text, in order.
std::vector<std::pair<std::string, std::string>> spec_entries(const torch::nn::Module& model) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& p : model.named_parameters(/*recurse=*/true))
    out.emplace_back(p.key(), shape_text(p.value()));
  for (const auto& b : model.named_buffers(/*recurse=*/true))
    out.emplace_back(b.key(), shape_text(b.value()));
  return out;
}

std::vector<std::pair<std::string, std::string>> parse_spec(const std::string& spec) {
  std::vector<std::pair<std::string, std::string>> out;
  std::istringstream lines(spec);
  std::string line;
  while (std::getline(lines, line)) {
    const auto space = line.find(' ');
    if (space == std::string::npos) continue;
    out.emplace_back(line.substr(0, space), line.substr(space + 1));
  }
  return out;
}

/// The first difference between the checkpoint's parameters and the model's, or "".
std::string spec_difference(const std::string& saved, const torch::nn::Module& model) {
  const auto want = parse_spec(saved);
  const auto have = spec_entries(model);
  std::map<std::string, std::string> saved_map(want.begin(), want.end());
  std::map<std::string, std::string> model_map(have.begin(), have.end());
  for (const auto& [name, shape] : have) {
    const auto it = saved_map.find(name);
    if (it == saved_map.end()) return "the model's parameter '" + name + "' " + shape + " is not in it";
    if (it->second != shape) {
      return "parameter '" + name + "' is " + it->second + " in the checkpoint but " + shape +
             " in the model";
    }
  }
  for (const auto& [name, shape] : want) {
    if (!model_map.count(name)) return "it has a parameter '" + name + "' " + shape + " the model lacks";
  }
  return "";
}

}  // namespace

void check_checkpointable(const torch::nn::Module& model) {
  // libtorch archives are TorchScript modules: each submodule name becomes a Python identifier.
  static const std::set<std::string> keywords = {
      "False", "None", "True", "and", "as", "assert", "async", "await", "break", "class",
      "continue", "def", "del", "elif", "else", "except", "finally", "for", "from", "global",
      "if", "import", "in", "is", "lambda", "nonlocal", "not", "or", "pass", "raise", "return",
      "try", "while", "with", "yield"};
  for (const auto& [name, shape] : spec_entries(model)) {
    std::size_t begin = 0;
    while (begin <= name.size()) {
      const std::size_t end = std::min(name.find('.', begin), name.size());
      const std::string part = name.substr(begin, end - begin);
      if (keywords.count(part)) {
        throw Error("parameter '" + name + "': the module name '" + part +
                    "' is a Python keyword, which libtorch's checkpoint format cannot store; "
                    "rename it in the model (e.g. '" + part + "_')");
      }
      begin = end + 1;
    }
  }
}

std::string parameter_spec(const torch::nn::Module& model) {
  std::string out;
  for (const auto& [name, shape] : spec_entries(model)) out += name + " " + shape + "\n";
  return out;
}

void save_checkpoint(const fs::path& path, const torch::nn::Module& model,
                     const torch::optim::Optimizer* optimizer, const TrainingState& state) {
  check_checkpointable(model);
  torch::serialize::OutputArchive archive;
  archive.write("version", c10::IValue(kCheckpointVersion));
  archive.write("model_spec", c10::IValue(parameter_spec(model)));
  archive.write("model_config", c10::IValue(state.model_config));
  torch::serialize::OutputArchive model_archive;
  model.save(model_archive);
  archive.write("model", model_archive);
  archive.write("has_optimizer", c10::IValue(optimizer != nullptr));
  if (optimizer != nullptr) {
    torch::serialize::OutputArchive optimizer_archive;
    optimizer->save(optimizer_archive);
    archive.write("optimizer", optimizer_archive);
  }
  archive.write("epoch", c10::IValue(state.epoch));
  archive.write("best_epoch", c10::IValue(state.best_epoch));
  archive.write("best_loss", c10::IValue(state.best_loss));
  archive.write("seed", c10::IValue(state.seed));
  archive.write("threads", c10::IValue(state.threads));
  archive.write("has_rng", c10::IValue(state.torch_rng.defined() && state.order_rng.defined()));
  if (state.torch_rng.defined() && state.order_rng.defined()) {
    archive.write("rng/torch", state.torch_rng);
    archive.write("rng/order", state.order_rng);
  }

  std::string extra_keys;
  for (const auto& [key, value] : state.extra) {
    extra_keys += (extra_keys.empty() ? "" : "\n") + key;
    archive.write("extra/" + key, c10::IValue(value));
  }
  archive.write("extra_keys", c10::IValue(extra_keys));

  AtomicPath out(path);
  try {
    archive.save_to(out.temp().string());
  } catch (const std::exception& e) {
    throw IoError(path.string() + ": cannot write checkpoint: " + e.what());
  }
  out.commit();
}

TrainingState load_checkpoint(const fs::path& path, torch::nn::Module& model,
                              torch::optim::Optimizer* optimizer) {
  if (!fs::exists(path)) throw IoError(path.string() + ": checkpoint does not exist");
  const std::string where = path.string() + ": ";
  check_zip_archive(path);
  torch::serialize::InputArchive archive;
  try {
    archive.load_from(path.string());
  } catch (const c10::Error& e) {
    throw IoError(where + "not a readable checkpoint: " + e.what_without_backtrace());
  } catch (const std::exception& e) {
    throw IoError(where + "not a readable checkpoint: " + e.what());
  }
  auto read = [&](const std::string& key) {
    c10::IValue value;
    if (!archive.try_read(key, value)) throw IoError(where + "not a skinlab checkpoint (no '" + key + "')");
    return value;
  };
  TrainingState state;
  try {
    const std::int64_t version = read("version").toInt();
    if (version != kCheckpointVersion) {
      throw IoError(where + "checkpoint layout version " + std::to_string(version) +
                    ", this build reads version " + std::to_string(kCheckpointVersion));
    }
    state.model_config = read("model_config").toStringRef();
    while (!state.model_config.empty() && std::isspace(static_cast<unsigned char>(state.model_config.back())))
      state.model_config.pop_back();
    const std::string difference = spec_difference(read("model_spec").toStringRef(), model);
    if (!difference.empty()) {
      throw IoError(where + "checkpoint does not match the model: " + difference +
                    " (the checkpoint's model config: " + state.model_config + ")");
    }
    torch::serialize::InputArchive model_archive;
    archive.read("model", model_archive);
    model.load(model_archive);
    if (optimizer != nullptr) {
      if (!read("has_optimizer").toBool()) throw IoError(where + "checkpoint has no optimizer state");
      torch::serialize::InputArchive optimizer_archive;
      archive.read("optimizer", optimizer_archive);
      optimizer->load(optimizer_archive);
    }
    state.epoch = read("epoch").toInt();
    state.best_epoch = read("best_epoch").toInt();
    state.best_loss = read("best_loss").toDouble();
    state.seed = read("seed").toInt();
    state.threads = read("threads").toInt();
    if (read("has_rng").toBool()) {
      archive.read("rng/torch", state.torch_rng);
      archive.read("rng/order", state.order_rng);
    }
    c10::IValue keys;
    if (archive.try_read("extra_keys", keys)) {
      std::istringstream lines(keys.toStringRef());
      for (std::string key; std::getline(lines, key);) {
        if (!key.empty()) state.extra[key] = read("extra/" + key).toDouble();
      }
    }
  } catch (const c10::Error& e) {
    throw IoError(where + "cannot read checkpoint: " + e.what_without_backtrace());
  } catch (const IoError&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError(where + "cannot read checkpoint: " + e.what());
  }
  return state;
}

}  // namespace skinlab::train
