// Journals (ensemble/journal.hpp): records appended by several writers are read back by index; a torn last line (a
// process killed mid-write) is skipped, a damaged line elsewhere is refused with file:line.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "fibernet/ensemble/journal.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
std::string fresh_dir(const std::string& name) {
    const auto d = std::filesystem::temp_directory_path() / ("fibernet_journal_" + name + std::to_string(::getpid()));
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    return d.string();
}
}  // namespace

TEST_CASE("journal: records of several writers, the first of an index wins", "[ensemble]") {
    const std::string d = fresh_dir("many");
    {
        JournalWriter a(d, "a"), b(d, "b");
        a.append({{"index", 2}, {"v", 1}});
        b.append({{"index", 0}, {"v", 2}});
        b.append({{"index", 2}, {"v", 3}});  // a duplicate (a sample run twice): counted, not used
        CHECK_THROWS_AS(JournalWriter(d, "a"), OutputError);  // tags are unique
    }
    const JournalContents c = read_journals(d);
    CHECK(c.files == 2);
    REQUIRE(c.records.size() == 2);
    CHECK(c.records.at(2)["v"] == 1);
    CHECK(c.records.at(0)["v"] == 2);
    CHECK(c.duplicates == 1);
    CHECK(c.torn == 0);
}

TEST_CASE("journal: a torn last line is skipped, a damaged middle line refused", "[ensemble]") {
    const std::string d = fresh_dir("torn");
    std::ofstream(d + "/x.jsonl") << "{\"index\":1}\n{\"index\":2,\"res";
    const JournalContents c = read_journals(d);
    CHECK(c.records.size() == 1);
    CHECK(c.torn == 1);
    std::ofstream(d + "/y.jsonl") << "{\"index\":3}\n{\"index\":-4}\n{\"index\":5}\n";
    CHECK_THROWS_WITH(read_journals(d), Catch::Contains("y.jsonl:2: not a journal record"));
}
