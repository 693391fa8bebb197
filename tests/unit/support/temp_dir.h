// A test fixture with a fresh temporary directory of the running test's own.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

namespace replica::tests {

// dir_: a directory of the running test's own (replica-<suite>-<pid>-<test> in the temporary
// directory), created empty before the test and removed after it.
class TempDirTest : public ::testing::Test
{
protected:
    void SetUp() override
    {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = std::filesystem::temp_directory_path() /
               ("replica-" + std::string(info->test_suite_name()) + "-" +
                std::to_string(::getpid()) + "-" + info->name());
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    // Writes 'text' to dir_/name; returns the path.
    std::string write(const std::string& name, const std::string& text) const
    {
        const auto p = dir_ / name;
        std::ofstream(p) << text;
        return p.string();
    }

    std::filesystem::path dir_;
};

} // namespace replica::tests
