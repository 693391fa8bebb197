// The cell rules every CSV reader shares (pipeline/csv/csv_cells.h): what a cell is, and which
// spellings of a number are read. The readers' own tests check that their errors name the line.
#include <pipeline/csv/csv_cells.h>

#include <gtest/gtest.h>

namespace replica::pipeline::csv {
namespace {

using Cells = std::vector<std::string>;

TEST(CsvCells, TrimsBlanksAndCarriageReturns)
{
    EXPECT_EQ(trimCell(" \t12.5\r"), "12.5");
    EXPECT_EQ(trimCell("a b"), "a b"); // inner blanks stay
    EXPECT_EQ(trimCell(" \t\r"), "");
    EXPECT_EQ(trimCell(""), "");
}

TEST(CsvCells, SplitsAtEveryCommaAndKeepsEmptyCells)
{
    EXPECT_EQ(splitCsvRow("a, b ,c"), (Cells{"a", "b", "c"}));
    // A missing value, in the middle or at the end, is an empty cell: the row is not shortened.
    EXPECT_EQ(splitCsvRow("1,,3"), (Cells{"1", "", "3"}));
    EXPECT_EQ(splitCsvRow("1,2,"), (Cells{"1", "2", ""}));
    EXPECT_EQ(splitCsvRow(",1"), (Cells{"", "1"}));
    EXPECT_EQ(splitCsvRow("1,2\r"), (Cells{"1", "2"}));
    EXPECT_EQ(splitCsvRow(""), (Cells{""}));
    EXPECT_EQ(splitCsvRow(" "), (Cells{""}));
}

// Spreadsheet exports: a byte order mark before the first cell, and cells in double quotes that
// may hold commas and doubled quotes (RFC 4180).
TEST(CsvCells, ReadsAByteOrderMarkAndQuotedCells)
{
    EXPECT_EQ(splitCsvRow("\xEF\xBB\xBFwavelength_nm,a"), (Cells{"wavelength_nm", "a"}));
    EXPECT_EQ(trimCell("\xEF\xBB\xBF 380"), "380");
    EXPECT_EQ(splitCsvRow(R"("380","0.5")"), (Cells{"380", "0.5"}));
    EXPECT_EQ(splitCsvRow(R"(" a, b ",c)"), (Cells{"a, b", "c"}));
    EXPECT_EQ(splitCsvRow(R"("say ""hi""",2)"), (Cells{R"(say "hi")", "2"}));
    EXPECT_EQ(splitCsvRow(R"(1,"",3)"), (Cells{"1", "", "3"}));
    // Text after the closing quote stays in the cell, so a reader refuses it as a number.
    EXPECT_EQ(splitCsvRow(R"("1"x,2)"), (Cells{"1x", "2"}));
    // An unterminated quote takes the rest of the line.
    EXPECT_EQ(splitCsvRow(R"("1,2)"), (Cells{"1,2"}));
    double v = 0.0;
    EXPECT_TRUE(parseFiniteNumber(splitCsvRow(R"("0.25")")[0], v));
    EXPECT_EQ(v, 0.25);
}

TEST(CsvCells, ReadsDecimalNumbersWithEitherSign)
{
    double v = 0.0;
    EXPECT_TRUE(parseFiniteNumber("-1.25e2", v));
    EXPECT_EQ(v, -125.0);
    EXPECT_TRUE(parseFiniteNumber("+2.5", v));
    EXPECT_EQ(v, 2.5);
    EXPECT_TRUE(parseFiniteNumber(".5", v));
    EXPECT_EQ(v, 0.5);
    EXPECT_TRUE(parseFiniteNumber("7.", v));
    EXPECT_EQ(v, 7.0);
    EXPECT_TRUE(parseFiniteNumber("1E-3", v));
    EXPECT_EQ(v, 1e-3);
    // Shortest round trip: the decimal a table was written with reads back to the same double.
    EXPECT_TRUE(parseFiniteNumber("0.1", v));
    EXPECT_EQ(v, 0.1);
    EXPECT_TRUE(parseFiniteNumber("4.9406564584124654e-324", v)); // the smallest subnormal
    EXPECT_GT(v, 0.0);
}

TEST(CsvCells, RefusesAnythingButOneWholeFiniteDecimalNumber)
{
    double v = 42.0;
    for (const char* bad : {"",      "+",      "-",    "+-1",   "++1",  "--1", "3x",   "1,5",
                            "1 2",   " 1",     "1 ",   "nan",   "-nan", "inf", "-inf", "infinity",
                            "1e999", "-1e999", "0x10", "0x1p3", "e5",   "1e",  "."}) {
        EXPECT_FALSE(parseFiniteNumber(bad, v)) << "'" << bad << "'";
    }
    EXPECT_EQ(v, 42.0) << "a refused cell must leave the value alone";
}

TEST(CsvCells, AQuotedCellIsEscapedAndCut)
{
    EXPECT_EQ(shownCell("abc"), "abc");
    EXPECT_EQ(shownCell("\x1b[2J"), "\\x1b[2J");
    EXPECT_EQ(shownCell(std::string_view("5\0"
                                         "0",
                                         3)),
              "5\\x000");
    const std::string big(10'000'000, 'x');
    EXPECT_EQ(shownCell(big), std::string(kShownCellChars, 'x') + "...");
}

} // namespace
} // namespace replica::pipeline::csv
