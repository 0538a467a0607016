// rccx::io: the strict readers every input path uses, and files replaced whole or not at all.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "rccx/io/data_files.hpp"
#include "rccx/io/file.hpp"
#include "rccx/io/input.hpp"
#include "rccx/io/parse.hpp"

namespace rccx::io {
namespace {

using namespace std::chrono_literals;

TEST(Parse, NumbersAreWholeFiniteAndInRange) {
  EXPECT_EQ(parse_number("12", "x"), 12.0);
  EXPECT_EQ(parse_number("-0.5", "x"), -0.5);
  EXPECT_EQ(parse_number("+3", "x"), 3.0);
  EXPECT_EQ(parse_number("1e-3", "x"), 1e-3);
  EXPECT_EQ(parse_number(".5", "x"), 0.5);
  EXPECT_EQ(parse_number("1e-400", "x"), 0.0);  // underflow is harmless
  for (const char* bad :
       {"",       " 5",   "5 ",  "5abc", "abc", "inf",   "-inf", "nan", "NaN", "1e400",
        "-1e400", "0x10", "--5", "+-5",  "5,",  "1.2.3", "e5",   "+",   "-",   "."}) {
    EXPECT_THROW(parse_number(bad, "x"), ParseError) << bad;
  }
  EXPECT_THROW(parse_number("11", "x", {0, 10, "mm"}), ParseError);
  try {
    parse_number("11", "--speed", {0, 10, "mm/s"});
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_STREQ(e.what(), "--speed: \"11\" is out of range; give a number from 0 to 10 mm/s");
  }
}

TEST(Parse, IntegersAndJoints) {
  EXPECT_EQ(parse_integer("42", "n", 0, 100), 42);
  EXPECT_EQ(parse_integer("-3", "n", -5, 5), -3);
  for (const char* bad : {"", "1.5", "1e2", "5abc", " 1", "0x1", "101", "99999999999999999999"}) {
    EXPECT_THROW(parse_integer(bad, "n", 0, 100), ParseError) << bad;
  }
  EXPECT_EQ(parse_joint("1", "j", 6), 0U);
  EXPECT_EQ(parse_joint("6", "j", 6), 5U);
  for (const char* bad : {"0", "7", "1.5", "-1", "+1", "", "1x", " 1"}) {
    EXPECT_THROW(parse_joint(bad, "j", 6), ParseError) << bad;
  }
}

TEST(Parse, DurationsTakeUnitsAndRanges) {
  EXPECT_EQ(parse_duration("28ms", "p", BareUnit::seconds, 0ns, 1s), 28ms);
  EXPECT_EQ(parse_duration("250us", "p", BareUnit::seconds, 0ns, 1s), 250us);
  EXPECT_EQ(parse_duration("28", "p", BareUnit::milliseconds, 0ns, 1s), 28ms);
  EXPECT_EQ(parse_duration("2", "p", BareUnit::seconds, 0ns, 10s), 2s);
  EXPECT_EQ(parse_duration("1500ns", "p", BareUnit::seconds, 0ns, 1s), 1500ns);
  EXPECT_EQ(parse_duration("1.5min", "p", BareUnit::seconds, 0ns, 100s), 90s);
  for (const char* bad : {"", "2m", "2 s", "inf", "1e300", "-1", "ms", "2sec", "nan s"}) {
    EXPECT_THROW(parse_duration(bad, "p", BareUnit::seconds, 0ns, 10s), ParseError) << bad;
  }
  EXPECT_DOUBLE_EQ(parse_seconds("0.5", "s", 0.001, 10), 0.5);
  EXPECT_THROW(parse_seconds("0", "s", 0.001, 10), ParseError);
}

TEST(Parse, ListsHaveTheirCount) {
  EXPECT_EQ(parse_number_list("1,2,3", "T", 3), (std::vector<double>{1, 2, 3}));
  EXPECT_THROW(parse_number_list("1,2", "T", 3), ParseError);
  EXPECT_THROW(parse_number_list("1,,3", "T", 3), ParseError);
  EXPECT_THROW(parse_number_list("1,2,", "T"), ParseError);
  EXPECT_THROW(parse_number_list("", "T"), ParseError);
}

TEST(Parse, TextIsUtf8AndNamesArePlain) {
  EXPECT_TRUE(is_utf8("plain"));
  EXPECT_TRUE(is_utf8("\xc3\xa9t\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80"));
  EXPECT_FALSE(is_utf8("\xff"));
  EXPECT_FALSE(is_utf8("\xc3"));              // cut short
  EXPECT_FALSE(is_utf8("\xc0\xaf"));          // overlong
  EXPECT_FALSE(is_utf8("\xed\xa0\x80"));      // surrogate
  EXPECT_FALSE(is_utf8("\xf4\x90\x80\x80"));  // above U+10FFFF
  EXPECT_NO_THROW(check_text("over the table", "note", 100));
  EXPECT_THROW(check_text(std::string("a\0b", 3), "note", 100), ParseError);
  EXPECT_THROW(check_text("a\nb", "note", 100), ParseError);
  EXPECT_THROW(check_text(std::string(101, 'a'), "note", 100), ParseError);
  EXPECT_NO_THROW(check_name("PICK_1.a-b", "name", 32));
  for (const char* bad : {"", "TWO WORDS", "\xc3\xa9", "a/b", "a\tb"}) {
    EXPECT_THROW(check_name(bad, "name", 32), ParseError) << bad;
  }
  EXPECT_EQ(quoted("a\x01\"b"), "\"a\\x01\\\"b\"");
}

class FileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("rccx-io-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::filesystem::permissions(dir_, std::filesystem::perms::owner_all);
    std::filesystem::remove_all(dir_);
  }
  static std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  std::size_t entries() const {
    return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(dir_),
                                                  std::filesystem::directory_iterator()));
  }
  std::filesystem::path dir_;
};

TEST_F(FileTest, ReplacesWholeAndLeavesNoTemporary) {
  const auto f = dir_ / "out.json";
  write_file_atomically(f, "first\n");
  write_file_atomically(f, "second\n");
  EXPECT_EQ(slurp(f), "second\n");
  EXPECT_EQ(entries(), 1U);
  EXPECT_EQ(read_file(f), "second\n");
}

TEST_F(FileTest, AnUncommittedFileLeavesTheTargetAsItWas) {
  const auto f = dir_ / "out.json";
  write_file_atomically(f, "good\n");
  {
    AtomicFile a(f);
    a.write("half");
  }  // no commit: an error or a signal on the way
  EXPECT_EQ(slurp(f), "good\n");
  EXPECT_EQ(entries(), 1U);
}

TEST_F(FileTest, ErrorsNameTheFileAndChangeNothing) {
  EXPECT_THROW(write_file_atomically(dir_, "x"), FileError);  // a directory
  EXPECT_THROW(write_file_atomically(dir_ / "missing" / "f", "x"), FileError);
  EXPECT_THROW((void)read_file(dir_), FileError);
  EXPECT_THROW((void)read_file(dir_ / "missing"), FileError);
  try {
    (void)read_file(dir_);
    FAIL();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos) << e.what();
  }
  if (::geteuid() != 0) {  // root writes anywhere
    std::filesystem::permissions(
        dir_, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    EXPECT_THROW(write_file_atomically(dir_ / "f", "x"), FileError);
  }
}

TEST_F(FileTest, ASymbolicLinkIsFollowedAndStays) {
  const auto target = dir_ / "target.csv";
  const auto link = dir_ / "link.csv";
  std::filesystem::create_symlink("target.csv", link);  // relative, and dangling at first
  write_file_atomically(link, "first\n");
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(slurp(target), "first\n");
  write_file_atomically(link, "second\n");
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(slurp(target), "second\n");
  EXPECT_EQ(entries(), 2U);  // no temporary left
}

TEST_F(FileTest, ANamedPipeIsWrittenInPlaceNotReplaced) {
  const auto fifo = dir_ / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // Nobody reads: refused at once rather than waited on, and the pipe stays a pipe.
  try {
    write_file_atomically(fifo, "x");
    FAIL() << "written to a pipe nobody reads";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("no process reads"), std::string::npos) << e.what();
  }
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  write_file_atomically(fifo, "rows\n");
  char got[16] = {};
  EXPECT_EQ(::read(reader, got, sizeof got), 5);
  EXPECT_STREQ(got, "rows\n");
  ::close(reader);
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the pipe was replaced by a regular file";
  EXPECT_EQ(entries(), 1U);
}

TEST_F(FileTest, ReadingANamedPipeOrADeviceIsRefusedAtOnce) {
  const auto fifo = dir_ / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW((void)read_file(fifo), FileError);         // would wait for a writer for ever
  EXPECT_THROW((void)read_file("/dev/zero"), FileError);  // would never end
}

TEST(ReadLine, LinesAreBoundedAndEndlessInputEnds) {
  std::string line;
  std::string problem;
  std::istringstream in("m 10\r\n" + std::string(5000, 'x') + "\nq");
  ASSERT_TRUE(read_line(in, line, problem));
  EXPECT_EQ(line, "m 10\r");
  EXPECT_EQ(problem, "");
  ASSERT_TRUE(read_line(in, line, problem));  // refused whole, the next line read
  EXPECT_EQ(line, "");
  EXPECT_NE(problem.find("5000 bytes"), std::string::npos) << problem;
  ASSERT_TRUE(read_line(in, line, problem));  // the last line, without its line end
  EXPECT_EQ(line, "q");
  EXPECT_EQ(problem, "");
  EXPECT_FALSE(read_line(in, line, problem));

  std::istringstream zeros(std::string(3u << 20, '\0'));  // /dev/zero, a binary file
  ASSERT_TRUE(read_line(zeros, line, problem));
  EXPECT_NE(problem.find("not lines of commands"), std::string::npos) << problem;
  EXPECT_FALSE(read_line(zeros, line, problem));  // reading stopped, not 3 MiB held
}

TEST(WriteAll, ReportsTheFailureOfAFullDevice) {
  const int fd = ::open("/dev/full", O_WRONLY);
  if (fd < 0) GTEST_SKIP() << "no /dev/full";
  EXPECT_EQ(write_all(fd, "x", 1), ENOSPC);
  ::close(fd);
}

// The shipped data: $RCCX_DATA_DIR alone when set, else the installed directory a program was
// compiled against, then the source tree; a file in none is an error naming where it looked.
class DataFiles : public ::testing::Test {
 protected:
  void SetUp() override { ::unsetenv("RCCX_DATA_DIR"); }
  void TearDown() override { ::unsetenv("RCCX_DATA_DIR"); }
};

TEST_F(DataFiles, TheSourceTreeHasTheCellsAndRobots) {
  for (const char* file : {"cells/cvarl.json", "robots/puma560.json"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(find_data_file(file))) << file;
  }
  EXPECT_EQ(data_dirs().front(), RCCX_TEST_SOURCE_DIR);  // no installed copy in the tree
}

TEST_F(DataFiles, TheInstalledDirectoryComesFirst) {
  const std::filesystem::path installed = testing::TempDir() + "rccx_data_installed";
  std::filesystem::create_directories(installed / "cells");
  std::ofstream(installed / "cells" / "cvarl.json") << "{}";
  EXPECT_EQ(find_data_file("cells/cvarl.json", installed.string()),
            installed / "cells" / "cvarl.json");
  // What it lacks is found further on.
  EXPECT_EQ(find_data_file("robots/puma560.json", installed.string()),
            std::filesystem::path(RCCX_TEST_SOURCE_DIR) / "robots" / "puma560.json");
  std::filesystem::remove_all(installed);
}

TEST_F(DataFiles, AnEnvironmentDirectoryIsTheOnlyPlace) {
  const std::string none = testing::TempDir() + "rccx_data_none";
  ::setenv("RCCX_DATA_DIR", none.c_str(), 1);
  ASSERT_EQ(data_dirs("/somewhere").size(), 1u);
  try {
    find_data_file("cells/cvarl.json");
    FAIL() << "found cells/cvarl.json in " << none;
  } catch (const DataFileError& e) {
    EXPECT_NE(std::string(e.what()).find(none), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("RCCX_DATA_DIR names"), std::string::npos) << e.what();
  }
  ::setenv("RCCX_DATA_DIR", "", 1);  // set empty: as if unset
  EXPECT_EQ(data_dirs().front(), RCCX_TEST_SOURCE_DIR);
}

TEST_F(DataFiles, AFileNowhereNamesEveryPlaceLookedIn) {
  try {
    find_data_file("cells/no_such_cell.json", "/nonexistent/share/rccx");
    FAIL() << "found cells/no_such_cell.json";
  } catch (const DataFileError& e) {
    const std::string what = e.what();
    for (const char* place :
         {"/nonexistent/share/rccx", RCCX_TEST_SOURCE_DIR, "set RCCX_DATA_DIR"}) {
      EXPECT_NE(what.find(place), std::string::npos) << place << " not in: " << what;
    }
  }
}

}  // namespace
}  // namespace rccx::io
