#include "runtime/disk_first_source.hpp"

#include "package/format.hpp"

namespace lodstream::runtime {

using schedule::PageKind;

DiskPages::DiskPages(DiskCache disk, const package::RootIndex& root) : disk_(std::move(disk)) {
  for (uint32_t id = 0; id < root.pages.size(); ++id)
    by_offset_.emplace(root.pages[id].offset,
                       std::pair(schedule::PageRef{PageKind::data, id}, root.pages[id]));
  for (uint32_t id = 0; id < root.index_pages.size(); ++id)
    by_offset_.emplace(root.index_pages[id].range.offset,
                       std::pair(schedule::PageRef{PageKind::index, id}, root.index_pages[id].range));
}

bool DiskPages::read(uint64_t offset, std::span<uint8_t> out) {
  const auto it = by_offset_.find(offset);
  if (it == by_offset_.end() || it->second.second.size != out.size()) return false;
  const auto& [page, range] = it->second;
  if (!disk_.read_page(page.kind, page.id, out) || package::checksum64(out) != range.checksum) return false;
  std::lock_guard lock(mutex_);
  served_.emplace(int(page.kind), page.id);
  return true;
}

bool DiskPages::take_served(const schedule::PageRef& page) {
  std::lock_guard lock(mutex_);
  return served_.erase({int(page.kind), page.id}) > 0;
}

void DiskFirstSource::read(uint64_t offset, std::span<uint8_t> out) const {
  if (!pages_->read(offset, out)) inner_->read(offset, out);
}

}  // namespace lodstream::runtime
