#include "net/url.hpp"

#include <charconv>

#include "core/error.hpp"

namespace lodstream {

UrlParts split_url(const std::string& url, const std::string& scheme) {
  if (url.rfind(scheme, 0) != 0)
    throw Error(url + (scheme.rfind("http", 0) == 0 ? ": not an " : ": not a ") + scheme + " URL");
  UrlParts u;
  const size_t slash = url.find('/', scheme.size());
  const std::string authority =
      url.substr(scheme.size(), slash == std::string::npos ? slash : slash - scheme.size());
  u.target = slash == std::string::npos ? "/" : url.substr(slash);
  const size_t colon = authority.rfind(':');
  u.host = authority.substr(0, colon);
  u.port = colon == std::string::npos ? "80" : authority.substr(colon + 1);
  unsigned port_number = 0;
  auto [end, ec] = std::from_chars(u.port.data(), u.port.data() + u.port.size(), port_number);
  if (u.host.empty() || ec != std::errc() || end != u.port.data() + u.port.size() || port_number == 0 ||
      port_number > 65535)
    throw Error(url + ": malformed URL (expected " + scheme + "HOST[:PORT]/PATH)");
  return u;
}

}  // namespace lodstream
