#include "framework/core/registry.hpp"

#include <gtest/gtest.h>

#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::expect_error;

struct Shape {
  virtual ~Shape() = default;
  virtual double area() const = 0;
};
struct Square : Shape {
  struct Options {
    double side = 1.0;
    static Options from(const config::Node& node) {
      Options o;
      config::Fields f(node, "shape 'square'");
      f.optional("side", o.side).check(o.side > 0, "side", "must be positive");
      f.finish();
      return o;
    }
  };
  explicit Square(Options o) : side(o.side) {}
  double area() const override { return side * side; }
  double side;
};

std::shared_ptr<Shape> make_square(const config::Node& node) {
  return std::make_shared<Square>(Square::Options::from(node));
}

TEST(Registry, CreatesByTypeWithOptions) {
  Registry<Shape> shapes("shape");
  shapes.add("square", make_square, "here:1");
  const auto config = config::Config::parse("shape: {type: square, side: 3}", "test.yaml");
  EXPECT_DOUBLE_EQ(shapes.create(config.root()["shape"])->area(), 9.0);
  EXPECT_TRUE(shapes.contains("square"));
  EXPECT_FALSE(shapes.contains("circle"));
}

TEST(Registry, DuplicateKeyNamesBothSites) {
  Registry<Shape> shapes("shape");
  shapes.add("square", make_square, "a.cpp:10");
  expect_error<RegistryError>([&] { shapes.add("square", make_square, "b.cpp:20"); },
                              {"shape registry", "duplicate key 'square'", "b.cpp:20", "a.cpp:10"});
}

TEST(Registry, RegistrarDefersDuplicateToCheck) {
  Registry<Shape> shapes("shape");
  Registrar<Shape> first(shapes, "square", make_square, "a.cpp", 1);
  EXPECT_NO_THROW(shapes.check());
  Registrar<Shape> second(shapes, "square", make_square, "b.cpp", 2);  // must not throw here
  expect_error<RegistryError>([&] { shapes.check(); }, {"duplicate key 'square'", "b.cpp:2"});
  const auto config = config::Config::parse("{type: square}");
  expect_error<RegistryError>([&] { shapes.create(config.root()); }, {"duplicate key"});
}

TEST(Registry, UnknownKeyListsEveryKnownKeyAndWhere) {
  Registry<Shape> shapes("shape");
  shapes.add("square", make_square, "x");
  shapes.add("rectangle", make_square, "y");
  const auto config = config::Config::parse("a:\n  shape: {type: circle}\n", "cfg.yaml");
  expect_error<RegistryError>([&] { shapes.create(config.root()["a"]["shape"]); },
                              {"cfg.yaml:2: a.shape: ", "unknown shape type 'circle'",
                               "known shape types: rectangle, square"});
}

TEST(Registry, EmptyRegistrySaysSo) {
  Registry<Shape> shapes("shape");
  const auto config = config::Config::parse("{type: circle}");
  expect_error<RegistryError>([&] { shapes.create(config.root()); },
                              {"unknown shape type 'circle'", "(none registered)"});
}

TEST(Registry, MissingTypeIsAConfigError) {
  Registry<Shape> shapes("shape");
  shapes.add("square", make_square, "x");
  const auto config = config::Config::parse("shape: {side: 2}\nother: 3\n", "cfg.yaml");
  expect_error<ConfigError>([&] { shapes.create(config.root()["shape"]); },
                            {"cfg.yaml:1: shape: ", "missing required field 'type'", "shape"});
  expect_error<ConfigError>([&] { shapes.create(config.root()["other"]); },
                            {"cfg.yaml:2: other: ", "expected a map with a 'type' key"});
}

TEST(Registry, PluginOptionsAreValidated) {
  Registry<Shape> shapes("shape");
  shapes.add("square", make_square, "x");
  const auto config = config::Config::parse("{type: square, sied: 2}", "cfg.yaml");
  expect_error<ConfigError>([&] { shapes.create(config.root()); },
                            {"cfg.yaml:1: sied: ", "unknown field of shape 'square'",
                             "did you mean 'side'?", "known fields: side, type"});
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab
