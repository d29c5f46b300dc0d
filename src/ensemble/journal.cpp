#include "fibernet/ensemble/journal.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <unistd.h>
#include <vector>

#include "fibernet/util/error.hpp"

namespace fibernet {

JournalWriter::JournalWriter(const std::string& dir, const std::string& tag) : path_(dir + "/" + tag + ".jsonl") {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_APPEND | O_CLOEXEC, 0644);
    if (fd_ < 0) throw OutputError("cannot create the journal '" + path_ + "' (" + std::strerror(errno) + ")");
}

JournalWriter::~JournalWriter() {
    if (fd_ >= 0) ::close(fd_);
}

void JournalWriter::append(const nlohmann::json& record) {
    const std::string line = record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
    std::size_t done = 0;
    while (done < line.size()) {  // one write(2) in practice; a short write is continued
        const ssize_t w = ::write(fd_, line.data() + done, line.size() - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) throw OutputError("cannot append to the journal '" + path_ + "' (" + std::strerror(errno) + ")");
        done += static_cast<std::size_t>(w);
    }
}

JournalContents read_journals(const std::string& dir) {
    JournalContents c;
    std::vector<std::string> files;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec))
        if (e.path().extension() == ".jsonl") files.push_back(e.path().string());
    if (ec) throw InputError("cannot read the journal directory '" + dir + "' (" + ec.message() + ")");
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
        std::ifstream is(f, std::ios::binary);
        if (!is) throw InputError("journal '" + f + "' cannot be opened");
        const std::string all((std::istreambuf_iterator<char>(is)), std::istreambuf_iterator<char>());
        ++c.files;
        std::size_t start = 0;
        for (int lineno = 1; start < all.size(); ++lineno) {
            const std::size_t end = all.find('\n', start);
            const bool last_unterminated = end == std::string::npos;
            const std::string line = all.substr(start, last_unterminated ? std::string::npos : end - start);
            start = last_unterminated ? all.size() : end + 1;
            nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
            const bool ok = j.is_object() && j.contains("index") && j["index"].is_number_unsigned();
            if (!ok) {
                if (last_unterminated) {
                    ++c.torn;
                    break;
                }
                throw InputError(f + ":" + std::to_string(lineno) + ": not a journal record (a JSON object with an index)");
            }
            const auto index = j["index"].get<std::size_t>();
            if (!c.records.emplace(index, std::move(j)).second) ++c.duplicates;
        }
    }
    return c;
}

}  // namespace fibernet
