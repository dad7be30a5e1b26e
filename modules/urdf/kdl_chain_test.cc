// The KDL chain built from urdfdom's model (kdl_chain.h) against kdl_parser's tree of the same URDF.
#include "urdf/kdl_chain.h"

#include <random>

#include <gtest/gtest.h>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

#include "support/temp_files.h"

namespace selfcal::urdf {
namespace {

std::string DataFile(const std::string& name) { return std::string(SELFCAL_SOURCE_DIR) + "/test/data/urdf/" + name; }

// Worst difference of the two chains' end frames over seeded joint values in [-pi, pi] (prismatic: 1 m).
double WorstDifference(const KDL::Chain& a, const KDL::Chain& b, int samples) {
  EXPECT_EQ(a.getNrOfJoints(), b.getNrOfJoints());
  KDL::ChainFkSolverPos_recursive fa(a), fb(b);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> angle(-3.14159, 3.14159);
  double worst = 0;
  for (int s = 0; s < samples; ++s) {
    KDL::JntArray q(a.getNrOfJoints());
    for (unsigned j = 0; j < q.rows(); ++j) q(j) = angle(rng);
    KDL::Frame pa, pb;
    EXPECT_GE(fa.JntToCart(q, pa), 0);
    EXPECT_GE(fb.JntToCart(q, pb), 0);
    for (int i = 0; i < 3; ++i) {
      worst = std::max(worst, std::abs(pa.p(i) - pb.p(i)));
      for (int j = 0; j < 3; ++j) worst = std::max(worst, std::abs(pa.M(i, j) - pb.M(i, j)));
    }
  }
  return worst;
}

TEST(KdlChain, EqualsKdlParsersChainOnEveryShippedUrdf) {
  const std::pair<const char*, const char*> cases[] = {{"ur5e.urdf", "camera_optical_frame"},
                                                       {"ur5e_named.urdf", "camera_color_optical_frame"},
                                                       {"puma560.urdf", "camera_optical_frame"},
                                                       {"panda.urdf", "camera_optical_frame"}};
  for (const auto& [file, tip] : cases) {
    SCOPED_TRACE(file);
    const std::string text = testing::ReadFile(DataFile(file));
    const ::urdf::ModelInterfaceSharedPtr model = ::urdf::parseURDF(text);
    ASSERT_TRUE(model);
    const std::string base = model->getRoot()->name;
    KDL::Tree tree;
    ASSERT_TRUE(kdl_parser::treeFromString(text, tree));
    KDL::Chain reference;
    ASSERT_TRUE(tree.getChain(base, tip, reference)) << base << " -> " << tip;
    Result<KDL::Chain> chain = KdlChainOf(*model, file, base, tip);
    ASSERT_TRUE(chain.ok()) << chain.status().message();
    EXPECT_GE(chain->getNrOfJoints(), 6u);
    EXPECT_LE(WorstDifference(*chain, reference, 500), 1e-12);
  }
}

TEST(KdlChain, RefusesAMissingLinkAndATipThatIsNotBelowTheBase) {
  const ::urdf::ModelInterfaceSharedPtr model = ::urdf::parseURDF(testing::ReadFile(DataFile("ur5e.urdf")));
  ASSERT_TRUE(model);
  Result<KDL::Chain> missing = KdlChainOf(*model, "ur5e.urdf", "base_link", "no_such_link");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().message(), "ur5e.urdf: no link `no_such_link`");
  Result<KDL::Chain> upwards = KdlChainOf(*model, "ur5e.urdf", "tool0", "base_link");
  ASSERT_FALSE(upwards.ok());
  EXPECT_EQ(upwards.status().message(), "ur5e.urdf: no chain from `tool0` to `base_link`");
}

}  // namespace
}  // namespace selfcal::urdf
