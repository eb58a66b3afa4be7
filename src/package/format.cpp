#include "package/format.hpp"

#include <xxhash.h>
#include <zstd.h>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "core/error.hpp"
#include "package/bytes.hpp"

namespace lodstream::package {

std::string ContentHash::hex() const {
  char text[33];
  std::snprintf(text, sizeof text, "%016llx%016llx", static_cast<unsigned long long>(high),
                static_cast<unsigned long long>(low));
  return text;
}

std::array<uint8_t, kHeaderSize> encode_header(const Header& h) {
  ByteWriter w;
  w.bytes.reserve(kHeaderSize);
  w.raw(kMagic);
  w.u32(h.version);
  w.u32(kHeaderSize);
  w.u64(h.file_size);
  w.u64(h.root_offset);
  w.u32(h.root_size);
  w.u32(h.root_raw_size);
  w.u64(h.root_checksum);
  w.u64(h.content_hash.low);
  w.u64(h.content_hash.high);
  std::array<uint8_t, kHeaderSize> out{};
  std::copy(w.bytes.begin(), w.bytes.end(), out.begin());
  return out;
}

Header decode_header(std::span<const uint8_t, kHeaderSize> bytes, uint64_t file_size,
                     const std::string& context) {
  ByteReader r(bytes, context);
  if (!std::equal(kMagic.begin(), kMagic.end(), r.bytes(kMagic.size(), "magic").begin())) {
    throw Error(context + ": not a .lods package (bad magic)");
  }
  Header h;
  h.version = r.u32();
  if (h.version != kFormatVersion) {
    throw Error(context + ": unsupported .lods format version " + std::to_string(h.version) +
                " (this reader reads " + std::to_string(kFormatVersion) + ")");
  }
  if (r.u32() != kHeaderSize) r.fail("unexpected header size");
  h.file_size = r.u64();
  if (h.file_size != file_size) {
    throw Error(context + ": file is " + std::to_string(file_size) + " bytes but its header says " +
                std::to_string(h.file_size) + " (truncated or appended to)");
  }
  h.root_offset = r.u64();
  h.root_size = r.u32();
  h.root_raw_size = r.u32();
  h.root_checksum = r.u64();
  h.content_hash.low = r.u64();
  h.content_hash.high = r.u64();
  if (file_size < 2 * kHeaderSize || h.root_offset < kHeaderSize || h.root_offset > file_size - kHeaderSize ||
      h.root_size > file_size - kHeaderSize - h.root_offset) {
    throw Error(context + ": root index range [" + std::to_string(h.root_offset) + ", +" +
                std::to_string(h.root_size) + ") is outside the file body");
  }
  if (h.root_raw_size > kMaxRootRawBytes) {
    throw Error(context + ": root index raw size " + std::to_string(h.root_raw_size) + " exceeds the limit");
  }
  return h;
}

uint64_t checksum64(std::span<const uint8_t> bytes) {
  return XXH3_64bits(bytes.data(), bytes.size());
}

ContentHasher::ContentHasher() : state_(XXH3_createState()) {
  if (!state_) throw Error("out of memory creating a hash state");
  XXH3_128bits_reset(static_cast<XXH3_state_t*>(state_));
}
ContentHasher::~ContentHasher() {
  XXH3_freeState(static_cast<XXH3_state_t*>(state_));
}
void ContentHasher::update(std::span<const uint8_t> bytes) {
  XXH3_128bits_update(static_cast<XXH3_state_t*>(state_), bytes.data(), bytes.size());
}
ContentHash ContentHasher::digest() const {
  XXH128_hash_t h = XXH3_128bits_digest(static_cast<const XXH3_state_t*>(state_));
  return {h.low64, h.high64};
}

std::vector<uint8_t> zstd_compress(std::span<const uint8_t> raw, int level, int min_match) {
  const std::span<const uint8_t> whole[1] = {raw};
  return zstd_compress_parts(whole, level, min_match);  // one part: the frame ZSTD_compress2 writes
}

std::vector<uint8_t> zstd_compress_parts(std::span<const std::span<const uint8_t>> parts, int level,
                                         int min_match) {
  // One context per thread, reset for each frame: a fresh context per frame allocated and cleared its match
  // tables every time (zstd's output does not depend on the context's history).
  thread_local std::unique_ptr<ZSTD_CCtx, size_t (*)(ZSTD_CCtx*)> cctx(ZSTD_createCCtx(), ZSTD_freeCCtx);
  if (!cctx) throw Error("out of memory creating a zstd context");
  ZSTD_CCtx_reset(cctx.get(), ZSTD_reset_session_and_parameters);
  size_t total = 0;
  for (std::span<const uint8_t> p : parts) total += p.size();
  // Each flush may add a block header (3 bytes) beyond the bound of the whole.
  std::vector<uint8_t> out(ZSTD_compressBound(total) + 8 * parts.size() + 32);
  size_t n = ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_compressionLevel, level);
  if (!ZSTD_isError(n) && min_match != 0) n = ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_minMatch, min_match);
  if (!ZSTD_isError(n)) n = ZSTD_CCtx_setPledgedSrcSize(cctx.get(), total);
  ZSTD_outBuffer o{out.data(), out.size(), 0};
  for (size_t i = 0; i < parts.size() && !ZSTD_isError(n); ++i) {
    ZSTD_inBuffer in{parts[i].data(), parts[i].size(), 0};
    const ZSTD_EndDirective end = i + 1 == parts.size() ? ZSTD_e_end : ZSTD_e_flush;
    do n = ZSTD_compressStream2(cctx.get(), &o, &in, end);
    while (!ZSTD_isError(n) && n != 0);  // the output buffer is large enough: one call normally suffices
  }
  if (parts.empty() && !ZSTD_isError(n)) {
    ZSTD_inBuffer in{nullptr, 0, 0};
    n = ZSTD_compressStream2(cctx.get(), &o, &in, ZSTD_e_end);
  }
  if (ZSTD_isError(n)) throw Error(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
  out.resize(o.pos);
  return out;
}

uint64_t zstd_declared_size(std::span<const uint8_t> frame, uint64_t max_size, const std::string& context) {
  const unsigned long long declared = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (declared == ZSTD_CONTENTSIZE_ERROR || declared == ZSTD_CONTENTSIZE_UNKNOWN) {
    throw Error(context + ": not a valid zstd frame");
  }
  if (declared > max_size) {
    throw Error(context + ": zstd frame holds " + std::to_string(declared) + " bytes, more than " +
                std::to_string(max_size) + " possible");
  }
  return declared;
}

void zstd_decompress_to(std::span<const uint8_t> frame, std::span<uint8_t> out, const std::string& context) {
  // One context per thread: ZSTD_decompress created and freed one (about 160 KB, allocated and set up) for
  // every frame.
  thread_local std::unique_ptr<ZSTD_DCtx, size_t (*)(ZSTD_DCtx*)> dctx(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!dctx) throw Error("out of memory creating a zstd context");
  const size_t n = ZSTD_decompressDCtx(dctx.get(), out.data(), out.size(), frame.data(), frame.size());
  if (ZSTD_isError(n)) throw Error(context + ": zstd: " + ZSTD_getErrorName(n));
  if (n != out.size()) throw Error(context + ": zstd frame decompressed to a different size");
}

std::vector<uint8_t> zstd_decompress(std::span<const uint8_t> frame, uint32_t raw_size,
                                     const std::string& context) {
  const uint64_t declared = zstd_declared_size(frame, UINT64_MAX, context);
  if (declared != raw_size) {
    throw Error(context + ": zstd frame holds " + std::to_string(declared) + " bytes, the index says " +
                std::to_string(raw_size));
  }
  std::vector<uint8_t> out(raw_size);
  zstd_decompress_to(frame, out, context);
  return out;
}

std::vector<uint8_t> zstd_decompress_at_most(std::span<const uint8_t> frame, uint64_t max_size,
                                             const std::string& context) {
  std::vector<uint8_t> out(zstd_declared_size(frame, max_size, context));
  zstd_decompress_to(frame, out, context);
  return out;
}

}  // namespace lodstream::package
