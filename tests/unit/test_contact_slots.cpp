#include <gtest/gtest.h>

#include "contact/slots.hpp"

using namespace grainlab;

TEST(Slots, NormalLinearNoTension) {
  EXPECT_DOUBLE_EQ(contact::normalLinear(2.0, 0.5, Vec3::UnitX()).x(), 1.0);
  EXPECT_DOUBLE_EQ(contact::normalLinear(2.0, -0.5, Vec3::UnitX()).norm(), 0.0);
}
