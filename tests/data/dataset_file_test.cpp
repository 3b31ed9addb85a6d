// The HDF5 dataset format (datasets/FORMAT.md): round trip, compression, and the reader's
// errors on truncated, foreign, wrong-version and inconsistent files.

#include "framework/data/dataset_file.hpp"

#include <H5Cpp.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "framework/core/atomic_file.hpp"
#include "tests/data/data_fixtures.hpp"
#include "tests/test_util.hpp"

namespace skinlab {
namespace {
namespace SKINLAB_UNITY_ID {  // unique per file in a unity build

using testing::expect_equal;
using testing::expect_error;
using testing::TempDir;

data::Dataset tiny_dataset() {
  data::Dataset d;
  d.characters = {testing::tiny_character("alpha"), testing::tiny_character("beta")};
  d.characters[1].animations.clear();
  d.characters[1].bind.clear();  // an augmented copy has no bind pose of its own
  d.characters[1].distances["hollow_dist"] = d.characters[1].distances["euclidean"];
  // beta's leaf bones have extent (format version 2); alpha keeps the paper's zero-length ones.
  d.characters[1].leaf_tips = d.characters[1].joints;
  d.characters[1].leaf_tips.bottomRows(1).array() += 0.25;
  d.characters[1].augmented_from = "alpha";  // as an augmented copy (alpha's, say)
  // beta carries a prior (preprocess.priors); alpha has none.
  const data::PreparedCharacter& b = d.characters[1];
  d.characters[1].priors["bone_heat"] =
      data::RowMatrixXf::Constant(b.num_vertices(), b.num_bones(), 1.0F / b.num_bones());
  d.splits["random"] = {{0}, {}, {1}};
  d.splits["by_skeleton"] = {{1}, {0}, {}};
  d.excluded = {{"folder", "bad.fbx", "bad.fbx: cannot read"}, {"zeroad", "x.pmd", "no bones"}};
  d.git_commit = "0123abcd";
  d.preparation = "preprocess: {}\ndistances: [{type: euclidean}]\n";
  return d;
}

TEST(DatasetFile, RoundTrip) {
  TempDir dir;
  const auto d = tiny_dataset();
  data::write_dataset(dir / "d.h5", d);
  const auto r = data::read_dataset(dir / "d.h5");
  ASSERT_EQ(r.characters.size(), 2u);
  expect_equal(d.characters[0], r.characters[0]);
  expect_equal(d.characters[1], r.characters[1]);
  EXPECT_EQ(r.git_commit, d.git_commit);
  EXPECT_EQ(r.preparation, d.preparation);
  ASSERT_EQ(r.splits.size(), 2u);
  EXPECT_EQ(r.splits.at("random").train, std::vector<int>{0});
  EXPECT_EQ(r.splits.at("random").test, std::vector<int>{1});
  EXPECT_EQ(r.splits.at("by_skeleton").val, std::vector<int>{0});
  ASSERT_EQ(r.excluded.size(), 2u);
  EXPECT_EQ(r.excluded[1].source, "zeroad");
  EXPECT_EQ(r.excluded[1].path, "x.pmd");
  EXPECT_EQ(r.excluded[1].reason, "no bones");
}

TEST(DatasetFile, CharacterUnitsAreSourceAndSkeletonFamilyOrVariantGroup) {
  TempDir dir;
  data::Dataset d = tiny_dataset();
  d.characters[0].source = "zeroad";
  d.characters[0].skeleton = "Biped";
  d.characters[0].group = "";  // written as its own name
  d.characters[1].source = "ogre";
  d.characters[1].skeleton = "Biped";
  d.characters[1].group = "alpha";
  data::write_dataset(dir / "u.h5", d);
  using Units = std::map<std::string, std::string>;
  // the same family name in two sources is two families
  EXPECT_EQ(data::read_character_units(dir / "u.h5", "family"),
            (Units{{"alpha", "zeroad/Biped"}, {"beta", "ogre/Biped"}}));
  EXPECT_EQ(data::read_character_units(dir / "u.h5", "group"),
            (Units{{"alpha", "zeroad/alpha"}, {"beta", "ogre/alpha"}}));
  expect_error<ConfigError>([&] { data::read_character_units(dir / "u.h5", "source"); },
                            {"u.h5", "unknown unit 'source'", "family or group"});
  expect_error<IoError>([&] { data::read_character_units(dir / "none.h5", "family"); }, {"none.h5"});
}

/// What an older skinlab wrote: format_version `version`, a variable-length string attribute and
/// a variable-length string list (their data in HDF5's global heap).
void write_variable_length_file(const std::filesystem::path& file, std::int64_t version) {
  H5::H5File f(file.string(), H5F_ACC_TRUNC);
  f.createAttribute("format_version", H5::PredType::STD_I64LE, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_INT64, &version);
  const H5::StrType vlen(H5::PredType::C_S1, H5T_VARIABLE);
  f.createAttribute("skinlab_git_commit", vlen, H5::DataSpace(H5S_SCALAR))
      .write(vlen, std::string("0123abcd"));
  const hsize_t n[1] = {2};
  const char* names[] = {"alpha", "beta"};
  f.createDataSet("character_names", vlen, H5::DataSpace(1, n)).write(names, vlen);
}

TEST(DatasetFile, OlderVersionsAreRefusedWithReRunPrepare) {
  TempDir dir;
  for (const std::int64_t version : {1, 2}) {
    const auto file = dir / ("v" + std::to_string(version) + ".h5");
    write_variable_length_file(file, version);
    expect_error<IoError>(
        [&] { data::read_dataset(file); },
        {file.filename().string(),
         "written by an older skinlab (format_version " + std::to_string(version),
         "re-run `skinlab prepare`"});
  }
}

TEST(DatasetFile, VariableLengthStringsAreRefusedBeforeTheirDataIsRead) {
  TempDir dir;
  const auto file = dir / "vlen.h5";
  write_variable_length_file(file, data::kFormatVersion);  // the current version, old strings
  expect_error<IoError>([&] { data::read_dataset(file); },
                        {"vlen.h5", "attribute 'skinlab_git_commit'", "variable-length strings",
                         "re-run `skinlab prepare`"});
  data::H5Reader r(file);
  expect_error<IoError>([&] { r.read_strings("/character_names"); },
                        {"vlen.h5", "dataset '/character_names'", "variable-length strings"});
}

TEST(DatasetFile, StringsAreFixedLength) {
  TempDir dir;
  data::write_dataset(dir / "d.h5", tiny_dataset());
  H5::H5File file((dir / "d.h5").string(), H5F_ACC_RDONLY);
  const H5::StrType names = file.openDataSet("/character_names").getStrType();
  EXPECT_FALSE(names.isVariableStr());
  EXPECT_EQ(names.getSize(), 5u);  // "alpha", the longest
  const H5::StrType licence = file.openGroup("/characters/alpha").openAttribute("licence").getStrType();
  EXPECT_FALSE(licence.isVariableStr());
  EXPECT_EQ(licence.getSize(), 7u);  // "CC0-1.0"
  EXPECT_EQ(licence.getCset(), H5T_CSET_UTF8);
}

TEST(DatasetFile, LeafTipsOfTheWrongShapeNameTheDataset) {
  TempDir dir;
  data::Dataset d = tiny_dataset();
  d.characters[1].leaf_tips.conservativeResize(d.characters[1].leaf_tips.rows() - 1, 3);
  data::write_dataset(dir / "t.h5", d);
  expect_error<IoError>([&] { data::read_dataset(dir / "t.h5"); },
                        {"t.h5", "'/characters/beta/leaf_tips'"});
}

TEST(DatasetFile, APriorOfTheWrongShapeOrSignNamesTheDataset) {
  TempDir dir;
  data::Dataset d = tiny_dataset();
  data::RowMatrixXf& prior = d.characters[1].priors.at("bone_heat");
  prior.conservativeResize(prior.rows(), prior.cols() - 1);
  data::write_dataset(dir / "p.h5", d);
  expect_error<IoError>([&] { data::read_dataset(dir / "p.h5"); },
                        {"p.h5", "'/characters/beta/priors/bone_heat'"});
  d = tiny_dataset();
  d.characters[1].priors.at("bone_heat")(2, 0) = -0.5F;
  data::write_dataset(dir / "n.h5", d);
  expect_error<IoError>([&] { data::read_dataset(dir / "n.h5"); },
                        {"n.h5", "'/characters/beta/priors/bone_heat'", "negative"});
}

TEST(DatasetFile, TheBindPoseIsKeptWithOrWithoutClipsAndCheckedForShape) {
  TempDir dir;
  data::Dataset d = tiny_dataset();
  d.characters[0].animations.clear();  // a character without a clip keeps its bind pose
  data::write_dataset(dir / "b.h5", d);
  const auto r = data::read_dataset(dir / "b.h5");
  ASSERT_EQ(r.characters[0].bind.size(), 36u);
  ASSERT_NE(r.characters[0].bind_pose(), nullptr);
  EXPECT_EQ(*r.characters[0].bind_pose(), d.characters[0].bind);
  EXPECT_EQ(r.characters[1].bind_pose(), nullptr);  // neither its own nor a clip's

  // A file without per-character bind poses (written before they were stored): a clip's.
  data::PreparedCharacter old = testing::tiny_character("old");
  old.bind.clear();
  ASSERT_NE(old.bind_pose(), nullptr);
  EXPECT_EQ(old.bind_pose(), &old.animations.front().bind);

  // The writer refuses a bind pose of the wrong size, naming the character; nothing is left.
  data::Dataset bad = d;
  bad.characters[0].bind.pop_back();
  expect_error<IoError>([&] { data::write_dataset(dir / "bad.h5", bad); },
                        {"bad.h5", "character 'alpha'", "bind pose of 35 values"});
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.h5"));
  // The reader names a stored bind pose of the wrong shape.
  {
    H5::H5File f((dir / "b.h5").string(), H5F_ACC_RDWR);
    f.unlink("/characters/alpha/bind");
    const hsize_t dims[2] = {2, 12};
    const std::vector<float> values(24, 0.5f);
    f.createDataSet("/characters/alpha/bind", H5::PredType::NATIVE_FLOAT, H5::DataSpace(2, dims))
        .write(values.data(), H5::PredType::NATIVE_FLOAT);
  }
  expect_error<IoError>([&] { data::read_dataset(dir / "b.h5"); },
                        {"b.h5", "'/characters/alpha/bind'", "expected 3×12"});
}

TEST(DatasetFile, RealCharacterArraysAreChunkedAndCompressed) {
  TempDir dir;
  data::Dataset d;
  auto c = testing::tiny_character("big");
  c.distances.at("euclidean").D = data::RowMatrixXf::Random(4, 400);  // 1600 ≥ kChunkThreshold
  d.characters.push_back(c);
  data::write_dataset(dir / "d.h5", d);
  H5::H5File file((dir / "d.h5").string(), H5F_ACC_RDONLY);
  const auto big = file.openDataSet("/characters/big/distances/euclidean/D").getCreatePlist();
  EXPECT_EQ(big.getLayout(), H5D_CHUNKED);
  EXPECT_GE(big.getNfilters(), 1);
  const auto small = file.openDataSet("/characters/big/F").getCreatePlist();
  EXPECT_EQ(small.getLayout(), H5D_CONTIGUOUS);
}

TEST(DatasetFile, ForeignAndBrokenFilesAreNamed) {
  TempDir dir;
  expect_error<IoError>([&] { data::read_dataset(dir / "none.h5"); },
                        {"none.h5", "does not exist"});
  const auto text = dir.write("text.h5", "hello, not HDF5\n");
  expect_error<IoError>([&] { data::read_dataset(text); }, {"text.h5", "not an HDF5 file"});

  {  // An HDF5 file of someone else: no format_version.
    data::H5Writer w(dir / "foreign.h5");
    w.write("matrix", data::RowMatrixXd(data::RowMatrixXd::Zero(2, 2)));
    w.commit();
  }
  expect_error<IoError>([&] { data::read_dataset(dir / "foreign.h5"); },
                        {"foreign.h5", "not a skinlab dataset", "format_version"});
  {
    data::H5Writer w(dir / "future.h5");
    w.write_attribute("/", "format_version", std::int64_t{4});
    w.commit();
  }
  expect_error<IoError>([&] { data::read_dataset(dir / "future.h5"); },
                        {"future.h5", "format_version 4 is not supported", "reads version 3"});

  // Truncated: a real dataset cut at half its size (as a crash during a copy would leave it).
  data::Dataset d = tiny_dataset();
  d.characters[0].distances.at("euclidean").D = data::RowMatrixXf::Random(4, 4000);
  data::write_dataset(dir / "full.h5", d);
  const auto size = std::filesystem::file_size(dir / "full.h5");
  std::filesystem::copy_file(dir / "full.h5", dir / "cut.h5");
  std::filesystem::resize_file(dir / "cut.h5", size / 2);
  expect_error<IoError>([&] { data::read_dataset(dir / "cut.h5"); }, {"cut.h5", "truncated"});
}

TEST(DatasetFile, OutOfRangeIndicesNameTheDataset) {
  TempDir dir;
  data::Dataset d = tiny_dataset();
  d.characters[1].F(1, 2) = 4;  // #V = 4
  data::write_dataset(dir / "f.h5", d);
  expect_error<IoError>([&] { data::read_dataset(dir / "f.h5"); },
                        {"f.h5", "'/characters/beta/F'", "entry 5 = 4", "vertex"});

  d = tiny_dataset();
  d.characters[0].distances.at("euclidean").topk_index(3, 1) = 4;  // #B = 4
  data::write_dataset(dir / "k.h5", d);
  expect_error<IoError>([&] { data::read_dataset(dir / "k.h5"); },
                        {"'/characters/alpha/distances/euclidean/topk_index'", "bone"});

  d = tiny_dataset();
  d.characters[0].bones(2, 1) = 3;  // #J = 3
  data::write_dataset(dir / "b.h5", d);
  expect_error<IoError>([&] { data::read_dataset(dir / "b.h5"); },
                        {"'/characters/alpha/bones'", "joint"});

  // Inconsistent CSR: overwrite indptr in place with a decreasing one.
  d = tiny_dataset();
  data::write_dataset(dir / "w.h5", d);
  {
    H5::H5File file((dir / "w.h5").string(), H5F_ACC_RDWR);
    const int bad[5] = {0, 3, 2, 5, 6};
    file.openDataSet("/characters/alpha/weights/indptr").write(bad, H5::PredType::NATIVE_INT);
  }
  expect_error<IoError>([&] { data::read_dataset(dir / "w.h5"); },
                        {"'/characters/alpha/weights/indptr'", "decreases at row 1"});

  testing::expect_error<IoError>(
      [&] {
        data::Dataset bad = tiny_dataset();
        bad.splits["random"].test = {2};
        data::write_dataset(dir / "s.h5", bad);
      },
      {"split 'random' index 2"});
  EXPECT_FALSE(std::filesystem::exists(dir / "s.h5"));
}

TEST(DatasetFile, ReadableByH5py) {
  // python3-h5py is installed by scripts/setup; without it this test fails (it does not skip),
  // as datasets/FORMAT.md promises the file reads in h5py.
  TempDir dir;
  data::Dataset d = tiny_dataset();
  d.characters[0].distances.at("euclidean").D = data::RowMatrixXf::Random(4, 400);  // compressed
  data::write_dataset(dir / "d.h5", d);
  const auto out = dir / "h5py.txt";
  // Values of a few datasets, then every dataset (read whole) and attribute (read) in the file,
  // named generically (<name>, <type>, <k>, <split>), and each name the format document does not
  // mention in a `code` span.
  const std::string script =
      "import h5py, numpy as np, re, sys\n"
      "f = h5py.File(sys.argv[1], 'r')\n"
      "c = f['characters/alpha']\n"
      "names = list(f['character_names'].asstr()[()])\n"
      "ip, ix, w = (c['weights/' + k][()] for k in ('indptr', 'indices', 'values'))\n"
      "rows = np.add.reduceat(w, ip[:-1])\n"
      "print(int(f.attrs['format_version']), names, c['V'].shape, c['F'][1].tolist(),\n"
      "      c['distances/euclidean/D'].shape, c['distances/euclidean/D'].compression,\n"
      "      np.allclose(rows, 1), list(f['splits/random/test'][()]),\n"
      "      c.attrs['licence'].decode(), c['animations/0/frames'].shape)\n"
      "def generic(path):\n"
      "    p = path.split('/')\n"
      "    for i in range(len(p) - 1):\n"
      "        if i == 0 and p[0] in ('characters', 'splits'):\n"
      "            p[1] = '<name>' if p[0] == 'characters' else '<split>'\n"
      "        if p[i] in ('distances', 'priors'): p[i + 1] = '<type>'\n"
      "        if p[i] == 'animations': p[i + 1] = '<k>'\n"
      "    return '/'.join(p)\n"
      "seen = set()\n"
      "def visit(name, o):\n"
      "    if isinstance(o, h5py.Dataset):\n"
      "        assert o[()].shape == o.shape\n"
      "        seen.add('dataset ' + generic(name))\n"
      "    for k in o.attrs:\n"
      "        o.attrs[k]\n"
      "        seen.add('attribute ' + generic(name) + '@' + k)\n"
      "visit('', f)\n"
      "f.visititems(visit)\n"
      "doc = open(sys.argv[2]).read()\n"
      "words = set(re.split(r'[/ ,{}()<>@]+', ' '.join(re.findall(r'`([^`]+)`', doc))))\n"
      "for item in sorted(seen):\n"
      "    leaf = re.split('[/@]', item.split(' ')[1])[-1].strip('<>')\n"
      "    print(item if leaf in words else item + ' (undocumented)')\n";
  const auto py = dir.write("check.py", script);
  const std::string command = "/usr/bin/python3 '" + py.string() + "' '" + (dir / "d.h5").string() +
                              "' '" SKINLAB_SOURCE_DIR "/datasets/FORMAT.md' >'" + out.string() +
                              "' 2>&1";
  const int status = std::system(command.c_str());
  const std::string printed = read_file(out);
  ASSERT_EQ(status, 0) << printed;
  EXPECT_EQ(printed,
            "3 ['alpha', 'beta'] (4, 3) [1, 3, 2] (4, 400) gzip True [1] CC0-1.0 (2, 3, 12)\n"
            // every table row of datasets/FORMAT.md, each read whole by h5py
            "attribute @format_version\n"
            "attribute @preparation\n"
            "attribute @skinlab_git_commit\n"
            "attribute characters/<name>/animations/<k>@fps\n"
            "attribute characters/<name>/animations/<k>@name\n"
            "attribute characters/<name>/weights@num_joints\n"
            "attribute characters/<name>@attribution\n"
            "attribute characters/<name>@augmented_from\n"
            "attribute characters/<name>@group\n"
            "attribute characters/<name>@licence\n"
            "attribute characters/<name>@path\n"
            "attribute characters/<name>@skeleton\n"
            "attribute characters/<name>@source\n"
            "attribute characters/<name>@subdivision_levels\n"
            "dataset character_names\n"
            "dataset characters/<name>/F\n"
            "dataset characters/<name>/V\n"
            "dataset characters/<name>/animations/<k>/bind\n"
            "dataset characters/<name>/animations/<k>/frames\n"
            "dataset characters/<name>/bind\n"
            "dataset characters/<name>/bones\n"
            "dataset characters/<name>/distances/<type>/D\n"
            "dataset characters/<name>/distances/<type>/targets\n"
            "dataset characters/<name>/distances/<type>/topk_distance\n"
            "dataset characters/<name>/distances/<type>/topk_index\n"
            "dataset characters/<name>/edges/geodesic\n"
            "dataset characters/<name>/edges/one_ring\n"
            "dataset characters/<name>/joint_names\n"
            "dataset characters/<name>/joints\n"
            "dataset characters/<name>/laplacian/indices\n"
            "dataset characters/<name>/laplacian/values\n"
            "dataset characters/<name>/leaf_tips\n"
            "dataset characters/<name>/normalisation\n"
            "dataset characters/<name>/parents\n"
      "dataset characters/<name>/priors/<type>\n"
            "dataset characters/<name>/vertex_map\n"
            "dataset characters/<name>/weights/indices\n"
            "dataset characters/<name>/weights/indptr\n"
            "dataset characters/<name>/weights/values\n"
            "dataset excluded/path\n"
            "dataset excluded/reason\n"
            "dataset excluded/source\n"
            "dataset splits/<split>/test\n"
            "dataset splits/<split>/train\n"
            "dataset splits/<split>/val\n")
      << printed;
}

}  // namespace SKINLAB_UNITY_ID
}  // namespace
}  // namespace skinlab
