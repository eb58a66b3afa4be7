// URLs of the client's transports: "http://HOST[:PORT]/PATH" (pull) and "ws://HOST[:PORT]/NAME" (push).
#pragma once

#include <string>

namespace lodstream {

struct UrlParts {
  std::string host, port, target;  // port "80" when absent; target "/" when no path
};

// Splits `url`, which must start with `scheme` ("http://", "ws://"). Throws lodstream::Error naming the URL
// when it does not, or when the host is empty or the port is not in 1..65535.
UrlParts split_url(const std::string& url, const std::string& scheme);

}  // namespace lodstream
