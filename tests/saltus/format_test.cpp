// saltus/format.cpp: numbers and CSV fields in the text Saltus writes.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "saltus/format.hpp"

namespace {

TEST(Format, NumbersKeepTheirDigitsAndNameTheNonFinite) {
  EXPECT_EQ(saltus::formatNumber(0.1234567), "0.123457");
  EXPECT_EQ(saltus::formatNumber(0.1234567, 3), "0.123");
  EXPECT_EQ(saltus::formatNumber(-0.0), "0");
  EXPECT_EQ(saltus::formatNumber(-1e-20, 3), "-1e-20");
  EXPECT_EQ(saltus::formatNumber(std::nan("")), "nan");
  EXPECT_EQ(saltus::formatNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(saltus::formatNumber(-std::numeric_limits<double>::infinity()), "-inf");
}

TEST(Format, CsvFieldsAreQuotedOnlyWhenTheyMustBe) {
  EXPECT_EQ(saltus::csvField("q.x"), "q.x");
  EXPECT_EQ(saltus::csvField("a,b"), "\"a,b\"");
  EXPECT_EQ(saltus::csvField("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(saltus::csvField("two\nlines"), "\"two lines\"");
}

}  // namespace
