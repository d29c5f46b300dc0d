#pragma once
// The record of an ensemble's finished samples (docs/scan.md, "Files"): JSON lines, one per sample, appended with
// one write(2) as each sample finishes. Every process writes a journal file of its own in the same directory, so
// ranks, shards and resumed runs never write into one another's files; a process killed mid-write leaves at most
// a torn last line, which readers skip.
#include <cstddef>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace fibernet {

class JournalWriter {
public:
    // Creates dir/<tag>.jsonl (dir must exist; an existing file is an error: tags are unique per process).
    JournalWriter(const std::string& dir, const std::string& tag);
    ~JournalWriter();
    JournalWriter(const JournalWriter&) = delete;
    JournalWriter& operator=(const JournalWriter&) = delete;
    // One record as one line; OutputError naming the file when the write fails.
    void append(const nlohmann::json& record);
    const std::string& path() const { return path_; }

private:
    std::string path_;
    int fd_ = -1;
};

struct JournalContents {
    std::map<std::size_t, nlohmann::json> records;  // by the records' "index"; the first of an index wins
    std::size_t duplicates = 0;                     // later records of an index already read
    std::size_t torn = 0;                           // torn last lines skipped
    std::size_t files = 0;
};

// Reads every *.jsonl file in dir (in name order). A line that is not a JSON object with a whole "index" is an
// InputError naming file:line, unless it is a file's unterminated last line (a write cut short).
JournalContents read_journals(const std::string& dir);

}  // namespace fibernet
