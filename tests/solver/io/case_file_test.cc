// Case file: time series, attributes and snapshots written and read back; XDMF references; resume.
#include "solver/io/case_file.h"

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>
#include <hdf5.h>

#include "capsim/version.h"
#include "solver/io/io_error.h"

namespace capsim::io {
namespace {

std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(CAPSIM_TEST_TMP) / "io_case";
  std::filesystem::create_directories(dir);
  return dir / name;
}

diagnostics::StepRecord record(int i) {
  const double t = 0.01 * i;
  return {t, 0.3 + 0.1 * std::sin(t), 1.2 + 0.01 * i, 0.8 - 1e-3 * i, std::remainder(-0.5 * t, M_PI),
          -0.01 * std::cos(3 * t), 4.18879 + 1e-9 * i, 13.2 + 1e-8 * i, {std::cos(t), std::sin(t), 0.0},
          1e-3 * (1 + std::sin(t)), 2e-3 * i};
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const Attribute* find(const std::vector<Attribute>& attrs, const std::string& key) {
  for (const auto& a : attrs)
    if (a.key == key) return &a;
  return nullptr;
}

TEST(CaseFile, RoundTripOfSeriesAttributesAndSnapshots) {
  const auto file = scratch("case.h5");
  const auto mesh = mesh::make_capsule_mesh(1, 2.0);
  const std::vector<Attribute> params{{"capillary_number", 0.3}, {"mesh_level", 1}, {"law", "skalak"}};
  diagnostics::TimeSeries expected;
  Eigen::Matrix3Xd x1 = mesh.nodes * 1.01;
  Eigen::VectorXd qn = Eigen::VectorXd::LinSpaced(mesh.num_nodes(), -1.0, 2.0);
  {
    CaseWriter w(file, params, {.buffer_rows = 64});
    for (int i = 0; i < 1000; ++i) {
      w.append(record(i));
      expected.push_back(record(i));
    }
    w.write_snapshot(0.0, 0, mesh, mesh.nodes);
    const std::vector<NodeField> fields{NodeField::scalar("q_n", qn), NodeField::vector("q", 2.0 * mesh.nodes)};
    w.write_snapshot(9.99, 999, mesh, x1, fields);
    w.set_attribute({"min_D12", 0.21});
    w.set_attribute({"regime", "tumbling"});
    EXPECT_EQ(w.rows(), 1000u);
    w.close();
  }
  const auto c = read_case_file(file);
  EXPECT_TRUE(c.series == expected);  // exact: binary64 stored and read back
  EXPECT_EQ(c.num_snapshots, 2);
  ASSERT_NE(find(c.attributes, "code_version"), nullptr);
  EXPECT_EQ(std::get<std::string>(find(c.attributes, "code_version")->value), kGitCommit);
  EXPECT_EQ(std::get<double>(find(c.attributes, "capillary_number")->value), 0.3);
  EXPECT_EQ(std::get<std::int64_t>(find(c.attributes, "mesh_level")->value), 1);
  EXPECT_EQ(std::get<std::string>(find(c.attributes, "law")->value), "skalak");
  EXPECT_EQ(std::get<std::string>(find(c.attributes, "regime")->value), "tumbling");
  EXPECT_EQ(std::get<double>(find(c.attributes, "min_D12")->value), 0.21);

  const auto s = read_snapshot(file, 1);
  EXPECT_EQ(s.t, 9.99);
  EXPECT_EQ(s.step, 999);
  EXPECT_EQ(s.positions, x1);
  EXPECT_EQ(s.elements, mesh.elements);
  ASSERT_EQ(s.fields.size(), 2u);
  for (const auto& f : s.fields) {
    if (f.name == "q_n") EXPECT_EQ(Eigen::VectorXd(f.values.transpose()), qn);
    else EXPECT_EQ(f.values, Eigen::MatrixXd(2.0 * mesh.nodes));
  }
  EXPECT_THROW(read_snapshot(file, 2), IoError);
}

TEST(CaseFile, XdmfReferencesExistingDatasetsOfTheRightShape) {
  const auto file = scratch("xdmf.h5");
  const auto mesh = mesh::make_sphere_mesh(1);
  for (auto topo : {XdmfTopology::Triangle6, XdmfTopology::LinearSplit}) {
    CaseWriter w(file, {}, {.topology = topo});
    const Eigen::VectorXd tau = Eigen::VectorXd::Ones(mesh.num_nodes());
    const std::vector<NodeField> fields{NodeField::scalar("tau1", tau)};
    w.write_snapshot(0.0, 0, mesh, mesh.nodes, fields);
    w.write_snapshot(0.5, 10, mesh, mesh.nodes, fields);
    w.close();
    const std::string xmf = slurp(w.xdmf_file());
    EXPECT_NE(xmf.find(topo == XdmfTopology::Triangle6 ? "TopologyType=\"Triangle_6\"" : "TopologyType=\"Triangle\""),
              std::string::npos);
    EXPECT_NE(xmf.find("<Time Value=\"0.5\"/>"), std::string::npos);
    // Every DataItem "Dims" → "file.h5:/path": the dataset exists with exactly these dimensions.
    const std::regex item(R"re(<DataItem Dimensions="([0-9 ]+)"[^>]*>([^:<]+):([^<]+)</DataItem>)re");
    hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    int items = 0;
    for (std::sregex_iterator it(xmf.begin(), xmf.end(), item), end; it != end; ++it, ++items) {
      EXPECT_EQ((*it)[2].str(), "xdmf.h5");
      const std::string path = (*it)[3].str();
      hid_t d = H5Dopen2(f, path.c_str(), H5P_DEFAULT);
      ASSERT_GE(d, 0) << path;
      hid_t sp = H5Dget_space(d);
      hsize_t dims[2] = {0, 0};
      const int rank = H5Sget_simple_extent_dims(sp, dims, nullptr);
      std::string shape = std::to_string(dims[0]) + (rank == 2 ? " " + std::to_string(dims[1]) : "");
      EXPECT_EQ(shape, (*it)[1].str()) << path;
      H5Sclose(sp);
      H5Dclose(d);
    }
    H5Fclose(f);
    EXPECT_EQ(items, 2 * 3);  // topology, geometry, tau1 per snapshot
    // Linear split: 4 flat triangles per P2 element, all node indices valid.
    const auto s = read_snapshot(file, 0);
    EXPECT_EQ(s.elements.size(), mesh.elements.size());
  }
}

TEST(CaseFile, ResumeKeepsTheCheckpointedSeriesAndDropsLaterSnapshots) {
  const auto file = scratch("resume.h5");
  const auto mesh = mesh::make_sphere_mesh(1);
  {
    CaseWriter w(file, {{"capillary_number", 0.9}});
    for (int i = 0; i < 1000; ++i) {
      w.append(record(i));
      if (i % 400 == 0) w.write_snapshot(record(i).t, i, mesh, mesh.nodes);  // t = 0, 4, 8
    }
  }  // destructor closes
  diagnostics::TimeSeries at_checkpoint;
  for (int i = 0; i < 500; ++i) at_checkpoint.push_back(record(i));  // up to t = 4.99
  {
    CaseWriter w = CaseWriter::resume(file, {}, at_checkpoint);
    EXPECT_EQ(w.rows(), 500u);
    for (int i = 500; i < 700; ++i) w.append(record(i));
    w.write_snapshot(record(699).t, 699, mesh, mesh.nodes);
    w.close();
  }
  const auto c = read_case_file(file);
  diagnostics::TimeSeries expected;
  for (int i = 0; i < 700; ++i) expected.push_back(record(i));
  EXPECT_TRUE(c.series == expected);
  EXPECT_EQ(c.num_snapshots, 3);  // t = 0, 4 kept; 8 dropped; 6.99 new
  EXPECT_EQ(read_snapshot(file, 2).step, 699);
  EXPECT_EQ(std::get<double>(find(c.attributes, "capillary_number")->value), 0.9);
  const std::string xmf = slurp(std::filesystem::path(file).replace_extension(".xmf"));
  EXPECT_EQ(xmf.find("<Time Value=\"8\"/>"), std::string::npos);
  EXPECT_NE(xmf.find("<Time Value=\"6.9900000000000002\"/>"), std::string::npos);
}

TEST(CaseFile, ErrorsNameTheFile) {
  const auto bad = scratch("no_such_dir") / "case.h5";
  try {
    CaseWriter w(bad, {});
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(CaseWriter(scratch("reserved.h5"), std::vector<Attribute>{{"code_version", "x"}}),
               std::invalid_argument);
  EXPECT_THROW(read_case_file(scratch("missing.h5")), IoError);
  // A text file is not a case file.
  std::ofstream(scratch("text.h5")) << "hello";
  EXPECT_THROW(read_case_file(scratch("text.h5")), IoError);
  const auto mesh = mesh::make_sphere_mesh(1);
  CaseWriter w(scratch("fields.h5"), {});
  const std::vector<NodeField> bad_name{NodeField::scalar("a/b", Eigen::VectorXd::Zero(mesh.num_nodes()))};
  EXPECT_THROW(w.write_snapshot(0, 0, mesh, mesh.nodes, bad_name), std::invalid_argument);
  const std::vector<NodeField> bad_size{NodeField::scalar("q_n", Eigen::VectorXd::Zero(3))};
  EXPECT_THROW(w.write_snapshot(0, 0, mesh, mesh.nodes, bad_size), std::invalid_argument);
}

TEST(CaseFile, AssigningOverAnOpenWriterWritesItsBufferedRows) {
  const auto first = scratch("first.h5"), second = scratch("second.h5");
  CaseWriter w(first, {}, {.buffer_rows = 64});
  for (int i = 0; i < 10; ++i) w.append(record(i));  // still buffered
  w = CaseWriter(second, {});
  EXPECT_EQ(read_case_file(first).series.size(), 10u);
  w.close();
  EXPECT_EQ(read_case_file(second).series.size(), 0u);
}

// A case file written before the bending columns existed (committed fixture, made by the code of 2b1b812:
// `capsim run - --set mesh.level=0 --set time.t_end=1 --stop-after 5`) reads with zero bending columns,
// and a resumed run continues in it with all columns.
TEST(CaseFile, FileFromBeforeTheBendingColumnsReadsAndResumes) {
  const auto file = scratch("pre_bending_case.h5");
  std::filesystem::copy_file(std::filesystem::path(CAPSIM_SOURCE_DIR) / "tests/solver/io/data/pre_bending_case.h5",
                             file, std::filesystem::copy_options::overwrite_existing);
  const auto c = read_case_file(file);
  ASSERT_GT(c.series.size(), 0u);
  EXPECT_TRUE(c.series.consistent());
  for (std::size_t i = 0; i < c.series.size(); ++i) {
    EXPECT_EQ(c.series.bending_energy[i], 0.0);
    EXPECT_EQ(c.series.max_bending_moment[i], 0.0);
    // Nor the 3D ellipsoid and the spin (added later still): not recorded, NaN.
    EXPECT_TRUE(std::isnan(c.series.La[i]) && std::isnan(c.series.ec_x3[i]) && std::isnan(c.series.spin[i]));
  }
  {
    CaseWriter w = CaseWriter::resume(file, {}, c.series);
    w.append(record(7));
    w.close();
  }
  const auto r = read_case_file(file);
  ASSERT_EQ(r.series.size(), c.series.size() + 1);
  EXPECT_EQ(r.series.max_bending_moment.back(), record(7).max_bending_moment);
  EXPECT_EQ(r.series.D12[0], c.series.D12[0]);
  EXPECT_EQ(r.series.La.back(), record(7).La);
  EXPECT_TRUE(std::isnan(r.series.spin.back())) << "record(7) has no spin measured";
  // Its old columns got their descriptions, the new ones were created with theirs.
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  for (const char* name : {"D12", "axis_tilt", "spin"}) {
    const hid_t d = H5Dopen2(f, (std::string("timeseries/") + name).c_str(), H5P_DEFAULT);
    EXPECT_GT(H5Aexists(d, "description"), 0) << name;
    H5Dclose(d);
  }
  H5Fclose(f);
}

// The columns say what they are: units and a description on every dataset of the time series.
TEST(CaseFile, EveryColumnHasUnitsAndADescription) {
  const auto file = scratch("described.h5");
  {
    CaseWriter w(file, {});
    w.append(record(0));
  }
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  int columns = 0;
  for (const char* name : {"t", "D12", "theta", "axis_tilt", "La", "Lb", "Lc", "ea_x1", "eb_x2", "ec_x3", "spin"}) {
    const hid_t d = H5Dopen2(f, (std::string("timeseries/") + name).c_str(), H5P_DEFAULT);
    ASSERT_GE(d, 0) << name;
    EXPECT_GT(H5Aexists(d, "units"), 0) << name;
    EXPECT_GT(H5Aexists(d, "description"), 0) << name;
    H5Dclose(d);
    ++columns;
  }
  H5Fclose(f);
  EXPECT_EQ(columns, 11);
}

// A snapshot written with its state's record holds the record's columns as attributes (t and step as before); one
// written without holds none.
TEST(CaseFile, SnapshotAttributesHoldTheStatesRecord) {
  const auto file = scratch("snapshot_record.h5");
  const auto mesh = mesh::make_capsule_mesh(1, 2.0);
  diagnostics::StepRecord rec = record(3);
  rec.La = 1.6;
  rec.Lb = 0.8;
  rec.Lc = 0.7;
  rec.ea = {0.6, 0.8, 0.0};
  rec.spin = -2.25;
  {
    CaseWriter w(file, {});
    w.write_snapshot(rec.t, 3, mesh, mesh.nodes, {}, &rec);
    w.write_snapshot(0.5, 50, mesh, mesh.nodes);
  }
  const Snapshot s = read_snapshot(file, 0);
  EXPECT_EQ(s.t, rec.t);
  EXPECT_EQ(s.step, 3);
  auto value = [&](const std::string& key) {
    const Attribute* a = find(s.attributes, key);
    return a ? std::get<double>(a->value) : std::nan("");
  };
  EXPECT_EQ(value("La"), 1.6);
  EXPECT_EQ(value("Lc"), 0.7);
  EXPECT_EQ(value("ea_x2"), 0.8);
  EXPECT_EQ(value("spin"), -2.25);
  EXPECT_EQ(value("D12"), rec.D12);
  EXPECT_EQ(find(s.attributes, "t"), nullptr) << "t is the snapshot's own attribute, read into Snapshot::t";
  EXPECT_TRUE(read_snapshot(file, 1).attributes.empty());
}

}  // namespace
}  // namespace capsim::io
