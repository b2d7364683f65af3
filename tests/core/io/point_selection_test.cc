// The classes a user names for LAS files (core/io/point_selection.h): lists, ranges, "all",
// and lists that name no class refused with what is wrong.
#include "core/io/point_selection.h"

#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace neuralmesh {
namespace {

using ::testing::HasSubstr;

TEST(PointSelectionTest, ParsesListsRangesAndAll) {
  absl::StatusOr<LasClasses> classes = ParseLasClasses("2,6");
  ASSERT_TRUE(classes.ok()) << classes.status();
  EXPECT_EQ(classes->count(), 2u);
  EXPECT_TRUE((*classes)[2] && (*classes)[6]);

  classes = ParseLasClasses(" 1-3 , 9,255 ");
  ASSERT_TRUE(classes.ok()) << classes.status();
  EXPECT_EQ(classes->count(), 5u);
  for (int c : {1, 2, 3, 9, 255}) EXPECT_TRUE((*classes)[c]) << c;

  classes = ParseLasClasses("all");
  ASSERT_TRUE(classes.ok()) << classes.status();
  EXPECT_TRUE(classes->all());
}

TEST(PointSelectionTest, RefusesWhatIsNoClass) {
  const struct {
    const char* text;
    const char* message;
  } refused[] = {
      {"", "the list is empty"},
      {"2,,6", "'' is not a class from 0 to 255"},
      {"ground", "'ground' is not a class from 0 to 255"},
      {"256", "'256' is not a class from 0 to 255"},
      {"2,-1", "'' is not a class from 0 to 255"},
      {"6-2", "the range '6-2' runs backwards"},
      {"1-x", "'x' is not a class from 0 to 255"},
  };
  for (const auto& r : refused) {
    const absl::StatusOr<LasClasses> classes = ParseLasClasses(r.text);
    EXPECT_EQ(classes.status().code(), absl::StatusCode::kInvalidArgument) << r.text;
    EXPECT_THAT(std::string(classes.status().message()), HasSubstr(r.message)) << r.text;
  }
}

}  // namespace
}  // namespace neuralmesh
