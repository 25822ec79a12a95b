// The docs (README.md and docs/*.md) point only inside the repository: every
// relative link names a file of the repository (and, after a '#', one of its
// headings), every `*.md` a doc names exists, and no doc names a place a user of
// the repository does not have.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "tests/support/text_file.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

const fs::path kRoot = fs::path(IMPACTLAB_SOURCE_DIR).lexically_normal();

// Places outside the repository that docs once pointed to.
constexpr std::string_view kOutside[] = {"/work/", "../shared", "external-sessions"};

using testing::ReadText;

std::vector<fs::path> Docs() {
  std::vector<fs::path> docs = {kRoot / "README.md"};
  for (const fs::directory_entry& entry : fs::directory_iterator(kRoot / "docs")) {
    if (entry.path().extension() == ".md") docs.push_back(entry.path());
  }
  std::sort(docs.begin(), docs.end());
  return docs;
}

// The text without its fenced code blocks (examples, whose `#` lines are no
// headings and whose paths are no links).
std::vector<std::string> ProseLines(const std::string& text) {
  std::vector<std::string> lines;
  bool fenced = false;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string line = text.substr(start, end - start);
    const std::size_t indent = line.find_first_not_of(' ');
    if (indent != std::string::npos && line.compare(indent, 3, "```") == 0) {
      fenced = !fenced;
    } else if (!fenced) {
      lines.push_back(line);
    }
    start = end + 1;
  }
  return lines;
}

// GitHub's anchor of a heading: lower case, spaces to '-', punctuation dropped
// but '-' and '_'. Non-ASCII characters are kept or dropped (letters are kept,
// dashes dropped); both anchors are accepted.
std::set<std::string> Anchors(const std::string& heading) {
  std::string keep, drop;
  for (const char c : heading) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x80) {
      keep += c;
    } else if (std::isalnum(u)) {
      keep += static_cast<char>(std::tolower(u));
      drop += static_cast<char>(std::tolower(u));
    } else if (c == ' ' || c == '-' || c == '_') {
      keep += c == ' ' ? '-' : c;
      drop += c == ' ' ? '-' : c;
    }
  }
  return {keep, drop};
}

std::set<std::string> AnchorsOf(const fs::path& doc) {
  std::set<std::string> anchors;
  for (const std::string& line : ProseLines(ReadText(doc))) {
    const std::size_t hashes = line.find_first_not_of('#');
    if (hashes == 0 || hashes == std::string::npos || line[hashes] != ' ') continue;
    anchors.merge(Anchors(line.substr(hashes + 1)));
  }
  return anchors;
}

bool InsideRepository(const fs::path& path) {
  const fs::path relative = path.lexically_normal().lexically_relative(kRoot);
  return !relative.empty() && *relative.begin() != "..";
}

TEST_CASE("docs: no doc names a place outside the repository") {
  for (const fs::path& doc : Docs()) {
    const std::string text = ReadText(doc);
    for (const std::string_view outside : kOutside) {
      if (text.find(outside) != std::string::npos) {
        FAIL_CHECK(doc.filename().string() << " names \"" << outside << "\"");
      }
    }
  }
}

TEST_CASE("docs: every link and every doc named leads to a file of the repository") {
  const std::regex link(R"(\]\(([^)\s]+)\))");
  const std::regex doc_name(R"([A-Za-z0-9_./-]*[A-Za-z0-9_-]\.md\b)");
  for (const fs::path& doc : Docs()) {
    const std::string name = doc.filename().string();
    for (const std::string& line : ProseLines(ReadText(doc))) {
      for (auto m = std::sregex_iterator(line.begin(), line.end(), link);
           m != std::sregex_iterator(); ++m) {
        const std::string target = (*m)[1];
        if (target.rfind("https://", 0) == 0 || target.rfind("http://", 0) == 0) continue;
        const std::size_t hash = target.find('#');
        const std::string file = target.substr(0, hash);
        const fs::path path = file.empty() ? doc : (doc.parent_path() / file).lexically_normal();
        INFO(name << ": link (" << target << ")");
        CHECK(fs::path(file).is_relative());
        CHECK(InsideRepository(path));
        CHECK(fs::exists(path));
        if (hash != std::string::npos && path.extension() == ".md" && fs::exists(path)) {
          CHECK(AnchorsOf(path).count(target.substr(hash + 1)) == 1);
        }
      }
      // A doc named in the text, linked or not (`session-format.md`): beside
      // this doc, or from the repository's root.
      for (auto m = std::sregex_iterator(line.begin(), line.end(), doc_name);
           m != std::sregex_iterator(); ++m) {
        const std::string named = m->str();
        if (named.find("//") != std::string::npos) continue;  // part of a URL
        INFO(name << ": names " << named);
        CHECK((fs::exists(doc.parent_path() / named) || fs::exists(kRoot / named)));
      }
    }
  }
}

}  // namespace
}  // namespace impactlab
