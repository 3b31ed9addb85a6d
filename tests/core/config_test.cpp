#include "framework/core/config.hpp"

#include <gtest/gtest.h>

#include "tests/test_util.hpp"

namespace skinlab::config {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using skinlab::testing::expect_error;
using skinlab::testing::TempDir;

TEST(Config, ChainOfBasesNearestWins) {
  TempDir dir;
  dir.write("a.yaml", "x: 1\ny: 1\nz: 1\n");
  dir.write("b.yaml", "_base_: a.yaml\ny: 2\nz: 2\n");
  const auto c = dir.write("c.yaml", "_base_: b.yaml\nz: 3\n");
  const Node root = Config::load(c).root();
  EXPECT_EQ(root["x"].as<int>(), 1);
  EXPECT_EQ(root["y"].as<int>(), 2);
  EXPECT_EQ(root["z"].as<int>(), 3);
  EXPECT_FALSE(root.has("_base_"));
}

TEST(Config, BasePathsAreRelativeToTheIncludingFile) {
  TempDir dir;
  dir.write("common/defaults.yaml", "seed: 7\n");
  dir.write("exp/base.yaml", "_base_: ../common/defaults.yaml\nname: base\n");
  const auto leaf = dir.write("exp/ablations/leaf.yaml", "_base_: ../base.yaml\nname: leaf\n");
  const Node root = Config::load(leaf).root();
  EXPECT_EQ(root["seed"].as<int>(), 7);
  EXPECT_EQ(root["name"].as<std::string>(), "leaf");
}

TEST(Config, SeveralBasesMergeInOrder) {
  TempDir dir;
  dir.write("a.yaml", "x: a\nonly_a: 1\n");
  dir.write("b.yaml", "x: b\nonly_b: 2\n");
  const auto c = dir.write("c.yaml", "_base_: [a.yaml, b.yaml]\n");
  const Node root = Config::load(c).root();
  EXPECT_EQ(root["x"].as<std::string>(), "b");
  EXPECT_EQ(root["only_a"].as<int>(), 1);
  EXPECT_EQ(root["only_b"].as<int>(), 2);
}

TEST(Config, MapsMergeDeeplyAndListsAreReplaced) {
  TempDir dir;
  dir.write("base.yaml",
            "model:\n  type: net\n  sizes: [256, 512]\n  mlp: {hidden: 64, act: relu}\n"
            "losses:\n  - {type: kl, weight: 1.0}\n  - {type: laplacian_smoothing, weight: 0.4}\n");
  const auto child = dir.write(
      "child.yaml", "_base_: base.yaml\nmodel:\n  sizes: [8]\n  mlp: {act: tanh}\n"
                    "losses:\n  - {type: kl}\n");
  const Node root = Config::load(child).root();
  EXPECT_EQ(root["model"]["type"].as<std::string>(), "net");
  EXPECT_EQ(root["model"]["sizes"].as<std::vector<int>>(), std::vector<int>{8});
  EXPECT_EQ(root["model"]["mlp"]["hidden"].as<int>(), 64);
  EXPECT_EQ(root["model"]["mlp"]["act"].as<std::string>(), "tanh");
  ASSERT_EQ(root["losses"].size(), 1u);
  EXPECT_FALSE(root["losses"][0].has("weight"));  // the list replaced, not merged element-wise
}

TEST(Config, OverridesAreTypedByYamlRules) {
  TempDir dir;
  const auto file = dir.write("c.yaml", "a: {b: 1}\nlist: [{w: 1}, {w: 2}]\nname: x\n");
  const Config config = Config::load(
      file, {"a.b=3", "a.c=0.5", "a.flag=true", "name=hello", "new.deep.key=[1, 2]",
             "list.1.w=5", "list[0].w=4"});
  const Node root = config.root();
  EXPECT_EQ(root["a"]["b"].as<int>(), 3);
  EXPECT_DOUBLE_EQ(root["a"]["c"].as<double>(), 0.5);
  EXPECT_TRUE(root["a"]["flag"].as<bool>());
  EXPECT_EQ(root["name"].as<std::string>(), "hello");
  EXPECT_EQ(root["new"]["deep"]["key"].as<std::vector<int>>(), (std::vector<int>{1, 2}));
  EXPECT_EQ(root["list"][0]["w"].as<int>(), 4);
  EXPECT_EQ(root["list"][1]["w"].as<int>(), 5);
  // An override is reported as the origin of its value.
  EXPECT_EQ(root["a"]["b"].origin().file, "override 'a.b=3'");
  EXPECT_EQ(root["name"].origin().str(), "override 'name=hello'");
}

TEST(Config, OverrideDoesNotChangeEarlierViews) {
  Config config = Config::parse("a: 1\n");
  const Node before = config.root();
  config.apply_override("a=2");
  EXPECT_EQ(before["a"].as<int>(), 1);
  EXPECT_EQ(config.root()["a"].as<int>(), 2);
}

TEST(Config, OverrideErrors) {
  Config config = Config::parse("a: 1\nlist: [1, 2]\n");
  expect_error<ConfigError>([&] { config.apply_override("a"); }, {"override 'a'", "key.path=value"});
  expect_error<ConfigError>([&] { config.apply_override("=3"); }, {"key.path=value"});
  expect_error<ConfigError>([&] { config.apply_override("a.b=3"); },
                            {"override 'a.b=3'", "'a' is a value, not a map"});
  expect_error<ConfigError>([&] { config.apply_override("list.5=3"); },
                            {"override 'list.5=3'", "list of 2 entries", "'5'"});
  expect_error<ConfigError>([&] { config.apply_override("a=[1,"); },
                            {"override 'a=[1,'", "not valid YAML"});
  expect_error<ConfigError>([&] { config.apply_override("_base_=x.yaml"); }, {"_base_"});
}

TEST(Config, ErrorsNameTheFileThatDefinedTheValue) {
  TempDir dir;
  dir.write("base.yaml", "\n\nseed: abc\n");
  const auto child = dir.write("child.yaml", "_base_: base.yaml\nother: 1\n");
  const Config config = Config::load(child);
  expect_error<ConfigError>([&] { config.root()["seed"].as<int>(); },
                            {(dir / "base.yaml").string() + ":3: seed: ",
                             "expected an integer, got 'abc'"});
}

TEST(Config, WrongTypes) {
  const Config config = Config::parse("i: 1.5\nb: maybe\nl: 3\ns: {a: 1}\nv: [1, x]\n", "t.yaml");
  const Node r = config.root();
  expect_error<ConfigError>([&] { r["i"].as<int>(); }, {"t.yaml:1: i: expected an integer, got '1.5'"});
  expect_error<ConfigError>([&] { r["b"].as<bool>(); }, {"t.yaml:2: b: expected a boolean"});
  expect_error<ConfigError>([&] { r["l"].as<std::vector<int>>(); },
                            {"t.yaml:3: l: expected a list of integers, got '3'"});
  expect_error<ConfigError>([&] { r["s"].as<std::string>(); },
                            {"t.yaml:4: s: expected a string, got a map"});
  expect_error<ConfigError>([&] { r["v"].as<std::vector<double>>(); },
                            {"t.yaml:5: v[1]: expected a number, got 'x'"});
  expect_error<ConfigError>([&] { r["missing"].as<double>(); },
                            {"missing: missing value (expected a number)"});
}

TEST(Config, MissingBaseCycleAndSyntaxErrors) {
  TempDir dir;
  const auto a = dir.write("a.yaml", "x: 1\n_base_: nope.yaml\n");
  expect_error<ConfigError>([&] { Config::load(a); },
                            {"a.yaml:2: _base_: file", "nope.yaml' does not exist"});
  dir.write("p.yaml", "_base_: q.yaml\n");
  const auto q = dir.write("q.yaml", "_base_: p.yaml\n");
  expect_error<ConfigError>([&] { Config::load(q); }, {"_base_ cycle", "q.yaml -> p.yaml -> q.yaml"});
  const auto bad = dir.write("bad.yaml", "a: 1\nb: [1, 2\n");
  expect_error<ConfigError>([&] { Config::load(bad); }, {"bad.yaml:", "YAML syntax error"});
  const auto list = dir.write("list.yaml", "- 1\n- 2\n");
  expect_error<ConfigError>([&] { Config::load(list); }, {"list.yaml:1", "must be a map"});
  expect_error<ConfigError>([&] { Config::load(dir / "absent.yaml"); },
                            {"absent.yaml: config file does not exist"});
}

struct Opts {
  int epochs = 10;
  double lr = 1e-3;
  std::string name;
  std::vector<int> sizes{256, 512};
};

Opts decode(const Node& node) {
  Opts o;
  Fields f(node, "trainer 'sgd'");
  f.required("name", o.name);
  f.optional("epochs", o.epochs).check(o.epochs > 0, "epochs", "must be positive");
  f.optional("lr", o.lr);
  f.optional("sizes", o.sizes);
  f.finish();
  return o;
}

TEST(Fields, DefaultsAndValues) {
  const Opts a = decode(Config::parse("{type: sgd, name: x}").root());
  EXPECT_EQ(a.epochs, 10);
  EXPECT_EQ(a.sizes, (std::vector<int>{256, 512}));
  const Opts b = decode(Config::parse("{name: y, epochs: 3, lr: 0.1, sizes: [1]}").root());
  EXPECT_EQ(b.epochs, 3);
  EXPECT_DOUBLE_EQ(b.lr, 0.1);
  EXPECT_EQ(b.sizes, std::vector<int>{1});
}

TEST(Fields, Errors) {
  auto parse = [](const std::string& yaml) { return Config::parse(yaml, "f.yaml").root()["t"]; };
  expect_error<ConfigError>([&] { decode(parse("t:\n  name: x\n  epoch: 3\n")); },
                            {"f.yaml:3: t.epoch: unknown field of trainer 'sgd'",
                             "did you mean 'epochs'?", "known fields: epochs, lr, name, sizes, type"});
  expect_error<ConfigError>([&] { decode(parse("t:\n  epochs: 3\n")); },
                            {"f.yaml:2: t: missing required field 'name' of trainer 'sgd' "
                             "(expected a string)"});
  expect_error<ConfigError>([&] { decode(parse("t: {name: x, epochs: -1}\n")); },
                            {"f.yaml:1: t.epochs: must be positive"});
  expect_error<ConfigError>([&] { decode(parse("t: {name: x, lr: fast}\n")); },
                            {"t.lr: expected a number, got 'fast'"});
  expect_error<ConfigError>([&] { decode(parse("t: 5\n")); },
                            {"f.yaml:1: t: expected a map of options for trainer 'sgd'"});
  expect_error<ConfigError>([&] { decode(parse("t: {name: x, zzzz: 1}\n")); },
                            {"unknown field", "known fields"});
}

TEST(Config, EmittedYamlReloadsToTheSameValues) {
  TempDir dir;
  dir.write("base.yaml", "model: {type: net, sizes: [1, 2]}\nseed: 3\n");
  const auto child = dir.write("child.yaml", "_base_: base.yaml\nmodel: {k: 3}\n");
  const Config config = Config::load(child, {"seed=4"});
  const auto again = dir.write("again.yaml", config.to_yaml());
  const Node root = Config::load(again).root();
  EXPECT_EQ(root["seed"].as<int>(), 4);
  EXPECT_EQ(root["model"]["k"].as<int>(), 3);
  EXPECT_EQ(root["model"]["sizes"].as<std::vector<int>>(), (std::vector<int>{1, 2}));
  EXPECT_EQ(root.keys(), (std::vector<std::string>{"model", "seed"}));
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab::config
