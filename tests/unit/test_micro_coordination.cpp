// Coordination and rattler removal on small hand-built networks whose answers are counted by hand.
#include <gtest/gtest.h>

#include "lab/micromechanics.hpp"

using namespace grainlab;
using namespace grainlab::lab;

namespace {

MicroNetwork network(int particles, const std::vector<std::pair<int, int>>& pairs,
                     const std::vector<int>& wallContactsOf = {}, bool frictionless = false) {
  MicroNetwork net;
  net.volume = 1.0;
  for (int i = 0; i < particles; ++i) {
    MicroParticle p;
    p.id = 10 + i;  // ids need not be indices
    p.radius = 1.0;
    p.frictionless = frictionless;
    net.particles.push_back(p);
  }
  for (auto [a, b] : pairs) {
    MicroContact c;
    c.a = 10 + a;
    c.b = 10 + b;
    net.contacts.push_back(c);
  }
  for (int a : wallContactsOf) {
    MicroContact c;
    c.a = 10 + a;
    c.b = 0;
    c.wall = true;
    net.contacts.push_back(c);
  }
  return net;
}

std::vector<std::pair<int, int>> complete(int n, int offset = 0) {
  std::vector<std::pair<int, int>> e;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) e.emplace_back(offset + i, offset + j);
  return e;
}

}  // namespace

TEST(Coordination, ChainUnravelsCompletely) {
  // 0-1-2-3: the ends have one contact; removing them leaves 1 and 2 with one each, and so on.
  const Coordination c = coordination(network(4, {{0, 1}, {1, 2}, {2, 3}}));
  EXPECT_DOUBLE_EQ(c.Z, 2.0 * 3 / 4);
  EXPECT_EQ(c.rattlers, 4u);
  EXPECT_DOUBLE_EQ(c.rattlerFraction, 1.0);
  EXPECT_FALSE(c.Zmech.has_value());  // nothing left to measure: null, not 0
  EXPECT_EQ(c.histogram, (std::vector<std::size_t>{0, 2, 2}));
}

TEST(Coordination, TriangleKeepsAndPendantGoes) {
  // Triangle 0-1-2 plus 3 hanging from 0, and 4 touching nothing.
  const Coordination c = coordination(network(5, {{0, 1}, {1, 2}, {2, 0}, {0, 3}}));
  EXPECT_DOUBLE_EQ(c.Z, 2.0 * 4 / 5);
  EXPECT_EQ(c.rattlers, 2u);
  EXPECT_TRUE(c.isRattler[3]);
  EXPECT_TRUE(c.isRattler[4]);
  ASSERT_TRUE(c.Zmech.has_value());
  EXPECT_DOUBLE_EQ(*c.Zmech, 2.0 * 3 / 3);
  EXPECT_EQ(c.histogram, (std::vector<std::size_t>{1, 1, 2, 1}));
}

TEST(Coordination, RemovalCascadesAlongAHangingChain) {
  // K4 core (0..3, 3 contacts each) with the chain 0-4-5-6: 6 goes, then 5, then 4.
  auto edges = complete(4);
  edges.insert(edges.end(), {{0, 4}, {4, 5}, {5, 6}});
  const Coordination c = coordination(network(7, edges));
  EXPECT_EQ(c.rattlers, 3u);
  for (int i : {4, 5, 6}) EXPECT_TRUE(c.isRattler[i]);
  EXPECT_DOUBLE_EQ(*c.Zmech, 2.0 * 6 / 4);
  EXPECT_DOUBLE_EQ(c.Z, 2.0 * 9 / 7);
}

TEST(Coordination, WallContactsCountForTheRuleNotForZ) {
  // 0 touches a wall and 1; 1 touches a wall and 0: two contacts each, both load-bearing.
  const Coordination c = coordination(network(2, {{0, 1}}, {0, 1}));
  EXPECT_EQ(c.rattlers, 0u);
  EXPECT_EQ(c.wallContacts, 2u);
  EXPECT_DOUBLE_EQ(c.Z, 1.0);
  EXPECT_DOUBLE_EQ(*c.Zmech, 1.0);
  // Without the walls both are rattlers.
  EXPECT_EQ(coordination(network(2, {{0, 1}})).rattlers, 2u);
}

TEST(Coordination, FrictionlessNeedsFourContacts) {
  // K4: three contacts each. Frictional: all stay; frictionless: all go.
  EXPECT_EQ(coordination(network(4, complete(4))).rattlers, 0u);
  EXPECT_EQ(coordination(network(4, complete(4), {}, true)).rattlers, 4u);
  // K5: four contacts each, frictionless: all stay, Zm = 4.
  const Coordination c = coordination(network(5, complete(5), {}, true));
  EXPECT_EQ(c.rattlers, 0u);
  EXPECT_DOUBLE_EQ(*c.Zmech, 4.0);
  // K4 frictionless plus one wall contact each: four contacts, all stay.
  EXPECT_EQ(coordination(network(4, complete(4), {0, 1, 2, 3}, true)).rattlers, 0u);
}

TEST(Coordination, RefusesUnknownParticlesAndSelfContacts) {
  MicroNetwork net = network(2, {{0, 1}});
  net.contacts[0].b = 99;
  EXPECT_THROW(coordination(net), std::invalid_argument);
  net.contacts[0].b = 10;
  EXPECT_THROW(coordination(net), std::invalid_argument);
  MicroNetwork twice = network(2, {{0, 1}});
  twice.particles[1].id = 10;
  EXPECT_THROW(coordination(twice), std::invalid_argument);
}
