// The checks every reader of a person's file goes through (pipeline/base/input_file.h,
// json_schema.h): regular files of bounded size, names that cannot leave a folder, and JSON held
// against a written schema with the offending path named.
#include <filesystem>
#include <fstream>
#include <limits>

#include <sys/stat.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/json_limits.h>
#include <pipeline/base/json_schema.h>
#include <pipeline/base/printable.h>

#include <gtest/gtest.h>

#include "../support/temp_dir.h"

namespace replica {
namespace {
namespace fs = std::filesystem;

using InputFile = tests::TempDirTest;

TEST_F(InputFile, ReadsRegularFilesAndRefusesEverythingElse)
{
    std::ofstream(dir_ / "a.json") << "{\"k\": 1}";
    auto ok = readInputFile(dir_ / "a.json", 100, "test");
    ASSERT_TRUE(ok) << ok.error().message;
    EXPECT_EQ(*ok, "{\"k\": 1}");

    const auto msg = [&](const fs::path& p, std::uintmax_t max = 100) {
        auto r = readInputFile(p, max, "test");
        return r ? std::string("(read)") : r.error().message;
    };
    EXPECT_EQ(msg(dir_ / "a.json", 5),
              (dir_ / "a.json").string() + ": 8 bytes, more than the 5 bytes a test file may hold");
    EXPECT_EQ(msg(dir_), dir_.string() + ": is a directory, not a test file; name a regular file");
    EXPECT_EQ(msg("/dev/zero"), "/dev/zero: is a device, not a test file; name a regular file");
    ASSERT_EQ(::mkfifo((dir_ / "fifo").c_str(), 0600), 0);
    EXPECT_EQ(msg(dir_ / "fifo"),
              (dir_ / "fifo").string() + ": is a FIFO, not a test file; name a regular file");
    fs::create_symlink(dir_ / "b", dir_ / "a");
    fs::create_symlink(dir_ / "a", dir_ / "b");
    EXPECT_NE(msg(dir_ / "a").find("a symbolic link loop"), std::string::npos) << msg(dir_ / "a");
    auto missing = readInputFile(dir_ / "none", 100, "test");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, ErrorCode::NotFound);
    // A /proc file says 0 bytes but is read up to the limit, then refused.
    EXPECT_NE(msg("/proc/self/maps", 16).find("more than the 16 bytes"), std::string::npos);
}

TEST(PlainName, AcceptsFileNamesAndRefusesPaths)
{
    for (const char* good : {"tungsten", "d65-fluorescent.exr", "lamp 2", "a_b.c"}) {
        EXPECT_TRUE(checkPlainName(good, "x")) << good;
    }
    for (const char* bad :
         {"", "../../escaped", "/etc/passwd", "a/b", "..", ".hidden", "a\nb", "tab\there"}) {
        EXPECT_FALSE(checkPlainName(bad, "x")) << bad;
    }
    EXPECT_FALSE(checkPlainName(std::string(129, 'a'), "x"));
    EXPECT_EQ(checkPlainName("../x", "booth.json: lights[0].name").error().message,
              "booth.json: lights[0].name: '../x' cannot name a file: use letters, digits, '.', "
              "'_', '-' (not starting with '.', at most 128 characters)");
}

TEST(JsonSchema, NamesThePathOfTheFirstViolation)
{
    using namespace json_schema;
    const JsonSchema s = object({
            {"name", string(8).optional()},
            {"size", array(number(0.0, 10.0), 2, 2)},
            {"ward", object({{"alpha", number(0.0, 5.0).optional()}}).optional()},
            {"texels", array(integer(1, 4096), 2, 2).optional()},
    });
    const auto err = [&](const char* text) {
        auto r = validateJson(nlohmann::json::parse(text), s, "f.json");
        return r ? std::string("ok") : r.error().message;
    };
    EXPECT_EQ(err(R"({"size": [1, 2]})"), "ok");
    EXPECT_EQ(err(R"({"name": 5, "size": [1, 2]})"),
              "f.json: /name: expected a string, found an integer");
    EXPECT_EQ(err(R"({"size": [1, 2], "ward": "x"})"),
              "f.json: /ward: expected an object, found a string");
    EXPECT_EQ(err(R"({"size": [1, 2], "ward": {"alpha": null}})"),
              "f.json: /ward/alpha: expected a number in [0, 5], found null");
    EXPECT_EQ(err(R"({"size": [1, 1e308]})"),
              "f.json: /size/1: expected a number in [0, 10], found 1e+308");
    EXPECT_EQ(err(R"({"size": [1]})"), "f.json: /size: expected an array of 2 items, found 1");
    EXPECT_EQ(err(R"({})"), "f.json: /size: required but missing");
    EXPECT_EQ(err(R"([1])"), "f.json: /: expected an object, found an array");
    EXPECT_EQ(err(R"({"size": [1, 2], "texels": [100000, 5]})"),
              "f.json: /texels/0: expected an integer in [1, 4096], found 100000");
    EXPECT_EQ(err(R"({"size": [1, 2], "texels": [2.5, 5]})"),
              "f.json: /texels/0: expected an integer in [1, 4096], found a number");
    EXPECT_EQ(err(R"({"size": [1, 2], "name": "123456789"})"),
              "f.json: /name: string longer than 8 characters");
    // Non-finite numbers cannot come from JSON text, but can from a document built in memory.
    nlohmann::json j = nlohmann::json::parse(R"({"size": [1, 2]})");
    j["size"][0] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(validateJson(j, s, "f.json"));
    // Unknown keys are warnings, with their path; the document still passes.
    std::vector<std::string> warnings;
    EXPECT_TRUE(validateJson(nlohmann::json::parse(R"({"size": [1, 2], "colour": 1,
                                                      "ward": {"beta": 2}})"),
                             s, "f.json", &warnings));
    EXPECT_EQ(warnings, (std::vector<std::string>{"f.json: /ward/beta: unknown key, ignored",
                                                  "f.json: /colour: unknown key, ignored"}));
}

// Depth counted by hand for each text: brackets in strings and escaped quotes do not count.
TEST(JsonLimits, DepthIsCountedOutsideStringsAndRefusedPastTheLimit)
{
    EXPECT_EQ(jsonDepth("1"), 0u);
    EXPECT_EQ(jsonDepth("{\"a\": [1, {\"b\": []}]}"), 4u);
    EXPECT_EQ(jsonDepth("[\"[[[\\\"[[\", []]"), 2u); // ["[[[\"[[", []]
    const std::string at = std::string(kMaxJsonDepth, '[') + std::string(kMaxJsonDepth, ']');
    EXPECT_TRUE(checkJsonLimits(at, "f.json"));
    const std::string past = "[" + at + "]";
    auto e = checkJsonLimits(past, "f.json");
    ASSERT_FALSE(e);
    EXPECT_EQ(e.error().message, "f.json: JSON nested 33 levels deep, more than the limit of 32");
    // The schema-checked reader refuses it before parsing, naming the file.
    auto parsed = parseJsonChecked(std::string(100000, '[') + std::string(100000, ']'),
                                   json_schema::any(), "deep.json");
    ASSERT_FALSE(parsed);
    EXPECT_EQ(parsed.error().message,
              "deep.json: JSON nested 100000 levels deep, more than the limit of 32");
    auto big = checkJsonLimits("[1, 2]", "f.json", 5);
    ASSERT_FALSE(big);
    EXPECT_EQ(big.error().message, "f.json: JSON of 6 bytes, more than the limit of 5");
}

// Lines and fields counted by hand; CGATS fields are separated by runs of spaces or tabs.
TEST(TableLimits, RowsAndFieldsAreCountedBeforeSplitting)
{
    EXPECT_TRUE(checkTableLimits("a,b\n1,2\n", "t.csv", ','));
    std::string wide = "x" + std::string(kMaxTableFields, ',') + "\n";
    auto w = checkTableLimits("a,b\n" + wide, "t.csv", ',');
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error().message, "t.csv:2: 4097 fields on one line, more than the limit of 4096 "
                                 "for a table");
    std::string cgats;
    for (std::size_t i = 0; i <= kMaxTableFields; ++i) {
        cgats += " \t 1";
    }
    auto c = checkTableLimits(cgats, "t.ti3", ' ');
    ASSERT_FALSE(c);
    EXPECT_EQ(c.error().message, "t.ti3:1: 4097 fields on one line, more than the limit of 4096 "
                                 "for a table");
    EXPECT_TRUE(checkTableLimits(std::string(kMaxTableRows, '\n'), "t.csv", ','));
    auto r = checkTableLimits(std::string(kMaxTableRows, '\n') + "1", "t.csv", ',');
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message,
              "t.csv: 1048577 lines, more than the limit of 1048576 for a table");
}

TEST(Printable, ControlCharactersAreEscapedAndLongTextCut)
{
    EXPECT_EQ(printable("\x1b]0;owned\x07ok\x7f"), "\\x1b]0;owned\\x07ok\\x7f");
    EXPECT_EQ(printable("a\nb"), "a\\x0ab");
    EXPECT_EQ(printable("a\nb", std::string_view::npos, true), "a\nb");
    EXPECT_EQ(printable("abcdef", 3), "abc...");
    EXPECT_EQ(printable("caf\xc3\xa9"), "caf\xc3\xa9"); // UTF-8 passes
}

} // namespace
} // namespace replica
