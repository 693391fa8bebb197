// The display layer's CSV readers on the shared cell rules (pipeline/csv/csv_cells.h, tested in
// tests/unit/csv): errors name source:line, and a row with a missing or non-finite value is
// refused, not shortened.
#include <pipeline/offline/display/viewing_angle_csv.h>

#include <gtest/gtest.h>

namespace replica::pipeline::display {
namespace {

TEST(ViewingAngleCsv, ReadsRatiosAndShiftsRelativeToTheOnAxisRow)
{
    const auto t = parseViewingAngleCsv("# white off axis\nangle_deg,X,Y,Z\n0,95,100,108\n"
                                        "30,76,80,90\n",
                                        "va.csv");
    ASSERT_TRUE(t) << t.error().message;
    ASSERT_EQ(t->angleDeg.size(), 2u);
    EXPECT_DOUBLE_EQ(t->luminanceRatio[1], 0.8);
    const double x0 = 95.0 / 303.0;
    const double x1 = 76.0 / 246.0;
    EXPECT_NEAR(t->dx[1], x1 - x0, 1e-15);
    EXPECT_DOUBLE_EQ(t->dx[0], 0.0);
}

TEST(ViewingAngleCsv, RefusesBadRowsNamingTheLine)
{
    const auto expectRefused = [](const std::string& text, const std::string& where) {
        const auto t = parseViewingAngleCsv(text, "va.csv");
        ASSERT_FALSE(t);
        EXPECT_EQ(t.error().code, ErrorCode::Corrupt);
        EXPECT_NE(t.error().message.find(where), std::string::npos) << t.error().message;
    };
    expectRefused("angle,X,Y,Z\n0,1,1,1\n", "va.csv:1");
    expectRefused("angle_deg,X,Y,Z\n0,95,100,108\n30,76,80,\n", "va.csv:3: '' is not a finite");
    expectRefused("angle_deg,X,Y,Z\n0,95,100,108,1\n", "va.csv:2: expected 4 values, found 5");
    expectRefused("angle_deg,X,Y,Z\n0,95,nan,108\n", "va.csv:2: 'nan'");
    expectRefused("angle_deg,X,Y,Z\n10,95,100,108\n", "va.csv:2: the first row must be on axis");
    expectRefused("angle_deg,X,Y,Z\n", "no measurements");
}

} // namespace
} // namespace replica::pipeline::display
