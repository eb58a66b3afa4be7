#include "runtime/disk_cache.hpp"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <optional>

#include "core/error.hpp"

namespace lodstream::runtime {

using schedule::PageKind;

namespace {

constexpr const char* kTempSuffix = ".tmp";

// (kind, id) of a page file name `d<id>` / `i<id>`, or nothing for any other name.
std::optional<schedule::PageRef> parse_name(const std::string& name) {
  if (name.size() < 2 || (name[0] != 'd' && name[0] != 'i')) return std::nullopt;
  uint32_t id = 0;
  const char* end = name.data() + name.size();
  const auto [at, ec] = std::from_chars(name.data() + 1, end, id);
  if (ec != std::errc() || at != end || name[1] == '+' || (name[1] == '0' && name.size() > 2))
    return std::nullopt;
  schedule::PageRef page;
  page.kind = name[0] == 'd' ? PageKind::data : PageKind::index;
  page.id = id;
  return page;
}

}  // namespace

DiskCache::DiskCache(const std::filesystem::path& root, const package::ContentHash& hash)
    : directory_(root / hash.hex()) {
  std::error_code ec;
  std::filesystem::create_directories(directory_, ec);
  if (ec) throw Error(directory_.string() + ": cannot create the cache directory: " + ec.message());
}

std::filesystem::path DiskCache::file(PageKind kind, uint32_t id) const {
  return directory_ / ((kind == PageKind::data ? "d" : "i") + std::to_string(id));
}

void DiskCache::store(PageKind kind, uint32_t id, std::span<const uint8_t> stored) {
  const std::filesystem::path target = file(kind, id);
  // The process id keeps two clients sharing a cache directory from writing the same temporary file.
  std::filesystem::path temp = target;
  temp += "." + std::to_string(getpid()) + kTempSuffix;
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(stored.data()), std::streamsize(stored.size()));
    if (!out) throw Error(temp.string() + ": cannot write a cached page");
  }
  std::error_code ec;
  std::filesystem::rename(temp, target, ec);
  if (ec) throw Error(target.string() + ": cannot store a cached page: " + ec.message());
}

bool DiskCache::read_page(PageKind kind, uint32_t id, std::span<uint8_t> out) const {
  std::ifstream in(file(kind, id), std::ios::binary | std::ios::ate);
  if (!in || uint64_t(in.tellg()) != out.size()) return false;
  in.seekg(0);
  in.read(reinterpret_cast<char*>(out.data()), std::streamsize(out.size()));
  return bool(in);
}

RestoredPages DiskCache::restore(ClientPackage& client, uint64_t budget_bytes) const {
  RestoredPages result;
  const package::RootIndex& root = client.reader().root();
  auto drop = [&](const std::filesystem::path& path, const std::string& why) {
    std::error_code ec;
    std::filesystem::remove(path, ec);
    result.warnings.push_back(path.string() + ": " + why + "; dropped from the cache");
  };

  std::vector<std::pair<schedule::PageRef, std::filesystem::path>> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(directory_, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.ends_with(kTempSuffix)) continue;  // a write in progress (or one a crash left behind)
    const std::optional<schedule::PageRef> page = parse_name(name);
    if (!page || !entry.is_regular_file()) {
      result.warnings.push_back(entry.path().string() + ": not a cached page file; ignored");
      continue;
    }
    files.emplace_back(*page, entry.path());
  }
  if (ec) result.warnings.push_back(directory_.string() + ": cannot list the cache: " + ec.message());
  // Index pages first (records are small and every later cut needs them), then data pages in page order.
  std::sort(files.begin(), files.end(), [](const auto& a, const auto& b) {
    return std::pair(a.first.kind == PageKind::data, a.first.id) <
           std::pair(b.first.kind == PageKind::data, b.first.id);
  });

  for (const auto& [page, path] : files) {
    const bool data = page.kind == PageKind::data;
    const size_t count = data ? root.pages.size() : root.index_pages.size();
    if (page.id >= count) {
      drop(path, "the package has no such page (" + std::to_string(count) + " pages)");
      continue;
    }
    const package::Range& range = data ? root.pages[page.id] : root.index_pages[page.id].range;
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) {
      drop(path, "cannot be read: " + ec.message());
      continue;
    }
    if (size != range.size) {
      drop(path, std::to_string(size) + " bytes where the package's page has " + std::to_string(range.size));
      continue;
    }
    if (data && client.cache().bytes() + range.raw_size > budget_bytes) {
      result.on_disk.push_back(page.id);
      continue;
    }
    if (const std::string why = load(client, page.kind, page.id, range.size); !why.empty()) {
      drop(path, why);
      continue;
    }
    ++result.pages;
    result.stored_bytes += range.size;
  }
  return result;
}

std::string DiskCache::load(ClientPackage& client, PageKind kind, uint32_t id, uint64_t size) const {
  std::vector<uint8_t> stored(size);
  if (!read_page(kind, id, stored)) return "cannot be read as a page of " + std::to_string(size) + " bytes";
  try {
    client.restore(kind, id, stored);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

std::string DiskCache::restore_page(ClientPackage& client, uint32_t id) const {
  const package::RootIndex& root = client.reader().root();
  if (id >= root.pages.size())
    return "data page " + std::to_string(id) + ": the package has " + std::to_string(root.pages.size());
  const std::string why = load(client, PageKind::data, id, root.pages[id].size);
  if (!why.empty()) {
    std::error_code ec;
    std::filesystem::remove(file(PageKind::data, id), ec);
    return file(PageKind::data, id).string() + ": " + why;
  }
  return "";
}

}  // namespace lodstream::runtime
