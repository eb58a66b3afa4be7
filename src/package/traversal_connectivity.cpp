#include "package/traversal_connectivity.hpp"

#include <algorithm>
#include <utility>

#include "core/error.hpp"
#include "package/bytes.hpp"

namespace lodstream::package {

namespace {

constexpr uint32_t kNone = UINT32_MAX;

// The front of traversal_connectivity.hpp, shared by encoder and decoder so that both apply the same rules.
class Front {
 public:
  // To process; in its loop, processed; out of the loops; in its loop, to process again once the next
  // cluster of a record starts (kDefer).
  enum State : uint32_t { kPending, kDone, kGone, kDeferred };
  struct Edge {
    uint32_t a, b, o, prev, next, state;
  };

  // A front for T triangles in `storage` (reused between calls): its edges pointer and size live in the
  // Front, a local of the caller, so that the compiler keeps them in registers.
  Front(std::vector<Edge>& storage, size_t triangles) {
    // A piece start adds 3 edges, every other triangle at most 2: no more than 3T edges, whatever the
    // symbols.
    if (storage.size() < 3 * triangles) storage.resize(3 * triangles);
    edges_ = storage.data();
  }
  // The first pending edge at or after e (edges are processed in creation order), or size() when none is.
  uint32_t gate(uint32_t e) const {
    while (e < size_ && edges_[e].state != kPending) ++e;
    return e;
  }
  uint32_t size() const { return size_; }
  const Edge& edge(uint32_t e) const { return edges_[e]; }
  // p of the gate's kLeft, n of its kRight (kNone unless its loop has 3 edges or more), and whether its loop
  // has exactly 3 (kEnd).
  uint32_t left(uint32_t e) const {
    const Edge& g = edges_[e];
    return g.prev != g.next ? edges_[g.prev].a : kNone;
  }
  uint32_t right(uint32_t e) const {
    const Edge& g = edges_[e];
    return g.prev != g.next ? edges_[g.next].b : kNone;
  }
  bool closes(uint32_t e) const {
    const Edge& g = edges_[e];
    return g.prev != g.next && edges_[g.next].next == g.prev;
  }

  void start(uint32_t v0, uint32_t v1, uint32_t v2) {
    const uint32_t at = size_;
    push(v0, v1, v2, at + 2, at + 1);
    push(v1, v2, v0, at, at + 2);
    push(v2, v0, v1, at + 1, at);
  }
  // kVertex and kSplit: the gate a -> b becomes a -> c, c -> b.
  void attach(uint32_t e, uint32_t c) {
    const uint32_t a = edges_[e].a, b = edges_[e].b, prev = edges_[e].prev, next = edges_[e].next;
    const uint32_t x = size_, y = x + 1;
    push(a, c, b, prev, y);
    push(c, b, a, x, next);
    edges_[prev].next = x;  // a loop has 2 edges or more: prev and next are not the gate
    edges_[next].prev = y;
    edges_[e].state = kGone;
  }
  // kLeft: P = p -> a and the gate become p -> b.
  void close_left(uint32_t e) {
    Edge &g = edges_[e], &p = edges_[g.prev];
    link(p.prev, g.next, p.a, g.b, g.a);
    p.state = g.state = kGone;
  }
  // kRight: the gate and N = b -> n become a -> n.
  void close_right(uint32_t e) {
    Edge &g = edges_[e], &n = edges_[g.next];
    link(g.prev, n.next, g.a, n.b, g.b);
    n.state = g.state = kGone;
  }
  // kEnd: the loop of 3 is gone.
  void close_loop(uint32_t e) {
    Edge& g = edges_[e];
    edges_[g.prev].state = edges_[g.next].state = g.state = kGone;
  }
  // kBoundary.
  void done(uint32_t e) { edges_[e].state = kDone; }
  // kDefer + d: the gate waits for cluster `cluster` (the current one + 1 + d); `deferred` lists (cluster,
  // gate) in the order they were deferred.
  void defer(uint32_t e, uint32_t cluster, std::vector<std::pair<uint32_t, uint32_t>>& deferred) {
    edges_[e].state = kDeferred;
    deferred.push_back({cluster, e});
  }
  // Cluster `cluster` starts: the gates deferred to it become gates again, processed before the rest
  // (`reopened`, in deferral order), so that it grows from the decoded part's border.
  static void reopen(Front& front, uint32_t cluster, std::vector<std::pair<uint32_t, uint32_t>>& deferred,
                     std::vector<uint32_t>& reopened, size_t& next_reopened) {
    reopened.clear(), next_reopened = 0;
    size_t kept = 0;
    for (const auto& [c, e] : deferred) {
      if (c != cluster) {
        deferred[kept++] = {c, e};
      } else if (front.edges_[e].state == kDeferred) {
        front.edges_[e].state = kPending, reopened.push_back(e);
      }
    }
    deferred.resize(kept);
  }
  // The next gate: the first pending reopened edge, else the first pending edge at or after `e` (advancing
  // e); size() when there is none.
  uint32_t next_gate(const std::vector<uint32_t>& reopened, size_t& next_reopened, uint32_t& e) const {
    while (next_reopened < reopened.size()) {
      const uint32_t r = reopened[next_reopened++];
      if (edges_[r].state == kPending) return r;
    }
    return e = gate(e);
  }

 private:
  void push(uint32_t a, uint32_t b, uint32_t o, uint32_t prev, uint32_t next) {
    Edge& x = edges_[size_++];
    x.a = a, x.b = b, x.o = o, x.prev = prev, x.next = next, x.state = kPending;
  }
  // A new edge a -> b (third corner o) between `before` and `after`.
  void link(uint32_t before, uint32_t after, uint32_t a, uint32_t b, uint32_t o) {
    const uint32_t x = size_;
    push(a, b, o, before, after);
    edges_[before].next = x;
    edges_[after].prev = x;
  }

  Edge* edges_;
  uint32_t size_ = 0;
};

void put_varint(std::vector<uint8_t>& out, uint32_t v) {
  for (; v >= 0x80; v >>= 7) out.push_back(uint8_t(v | 0x80));
  out.push_back(uint8_t(v));
}

}  // namespace

TraversalCode encode_traversal(std::span<const uint32_t> indices, uint32_t V,
                               std::span<const uint32_t> cluster_triangles) {
  const uint32_t T = uint32_t(indices.size() / 3);
  // cluster_of[t]: the cluster of triangle t (all 0 without clusters).
  std::vector<uint32_t> cluster_of(T, 0);
  for (uint32_t c = 0, t = 0; c < cluster_triangles.size(); ++c)
    for (uint32_t k = 0; k < cluster_triangles[c] && t < T; ++k) cluster_of[t++] = c;
  uint32_t cluster = 0;  // the cluster being encoded: triangles [.., cluster_end) of the output
  uint32_t cluster_end = cluster_triangles.empty() ? T : cluster_triangles[0];
  TraversalCode code;
  code.indices.reserve(indices.size());
  code.predictors.reserve(3 * size_t(V));
  // Outgoing half-edges per vertex (corner c = 3t + k goes from indices[c] to the next corner of t).
  std::vector<uint32_t> first(size_t(V) + 1, 0), corners(indices.size());
  for (uint32_t i : indices) ++first[i + 1];
  for (uint32_t v = 0; v < V; ++v) first[v + 1] += first[v];
  {
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (uint32_t c = 0; c < indices.size(); ++c) corners[fill[indices[c]]++] = c;
  }
  auto next_corner = [](uint32_t c) { return c % 3 == 2 ? c - 2 : c + 1; };
  std::vector<uint8_t> encoded(T, 0);
  std::vector<uint32_t> decoded(V, kNone);  // decoded[input vertex] = its number
  auto add_vertex = [&](uint32_t input, uint32_t o1, uint32_t o2, uint32_t o) {
    decoded[input] = uint32_t(code.order.size());
    code.order.push_back(input);
    code.predictors.insert(code.predictors.end(), {o1, o2, o});
    return decoded[input];
  };
  auto emit = [&](uint32_t a, uint32_t b, uint32_t c) { code.indices.insert(code.indices.end(), {a, b, c}); };

  std::vector<Front::Edge> edges;
  Front front(edges, T);
  uint32_t scan = 0;  // triangles below it are encoded
  uint32_t done = 0;  // triangles emitted
  uint32_t e = 0;     // the scan for gates
  std::vector<std::pair<uint32_t, uint32_t>> deferred;
  std::vector<uint32_t> reopened;
  size_t next_reopened = 0;
  while (done < T) {
    if (done == cluster_end) {
      cluster_end += cluster_triangles[++cluster];
      Front::reopen(front, cluster, deferred, reopened, next_reopened);
    }
    const uint32_t gate = front.next_gate(reopened, next_reopened, e);
    if (gate == front.size()) {
      while (encoded[scan]) ++scan;  // the first triangle left, of the current cluster
      encoded[scan] = 1;
      uint32_t corner[3];
      for (int k = 0; k < 3; ++k) {
        const uint32_t input = indices[3 * scan + k];
        const uint32_t next = uint32_t(code.order.size());
        if (decoded[input] != kNone) {
          put_varint(code.references, next - decoded[input]);
          corner[k] = decoded[input];
        } else {
          put_varint(code.references, 0);
          const uint32_t from = k > 0 ? corner[k - 1] : next > 0 ? next - 1 : V;
          corner[k] = add_vertex(input, from, from, from);
        }
      }
      front.start(corner[0], corner[1], corner[2]);
      emit(corner[0], corner[1], corner[2]);
      ++done;
      continue;
    }
    const Front::Edge g = front.edge(gate);
    // The triangle across a -> b holds half-edge b -> a; one of a later cluster defers the gate.
    const uint32_t a_in = code.order[g.a], b_in = code.order[g.b];
    uint32_t across = kNone, later = kNone;  // later: the first later cluster across
    for (uint32_t i = first[b_in]; i < first[b_in + 1] && across == kNone; ++i) {
      const uint32_t c = corners[i];
      if (encoded[c / 3] || indices[next_corner(c)] != a_in) continue;
      if (cluster_of[c / 3] == cluster) across = c;
      later = std::min(later, cluster_of[c / 3]);
    }
    if (across == kNone && later != kNone && later - cluster - 1 < kDeferClusters) {
      code.symbols.push_back(uint8_t(kDefer + (later - cluster - 1)));
      front.defer(gate, later, deferred);
      continue;
    }
    if (across == kNone) {
      code.symbols.push_back(kBoundary);
      front.done(gate);
      continue;
    }
    encoded[across / 3] = 1;
    const uint32_t c_in = indices[next_corner(next_corner(across))];
    uint32_t c = decoded[c_in];
    if (c == kNone) {
      code.symbols.push_back(kVertex);
      c = add_vertex(c_in, g.a, g.b, g.o);
      front.attach(gate, c);
    } else if (front.closes(gate) && c == front.left(gate)) {
      code.symbols.push_back(kEnd);
      front.close_loop(gate);
    } else if (c == front.left(gate)) {
      code.symbols.push_back(kLeft);
      front.close_left(gate);
    } else if (c == front.right(gate)) {
      code.symbols.push_back(kRight);
      front.close_right(gate);
    } else {
      code.symbols.push_back(kSplit);
      put_varint(code.references, uint32_t(code.order.size()) - 1 - c);
      front.attach(gate, c);
    }
    emit(g.b, g.a, c);
    ++done;
  }
  for (uint32_t v = 0; v < V; ++v) {
    if (decoded[v] != kNone) continue;
    const uint32_t from = code.order.empty() ? V : uint32_t(code.order.size()) - 1;
    add_vertex(v, from, from, from);
  }
  return code;
}

void decode_traversal(std::span<const uint8_t> symbols, std::span<const uint8_t> references, uint32_t T,
                      uint32_t V, uint32_t* indices, uint32_t* predictors, const std::string& where,
                      std::span<const uint32_t> cluster_triangles) {
  ByteReader refs(references, where);
  auto fail = [&](const char* what) { throw Error(where + ": corrupted connectivity (" + what + ")"); };
  thread_local std::vector<Front::Edge> edges;
  Front front(edges, T);
  uint32_t next = 0;  // the next new vertex
  const uint8_t* symbol = symbols.data();
  const uint8_t* const symbols_end = symbol + symbols.size();
  uint32_t* out = indices;
  const uint32_t* const end = indices + 3 * size_t(T);
  uint32_t e = 0;  // the scan for gates
  thread_local std::vector<std::pair<uint32_t, uint32_t>> deferred;
  thread_local std::vector<uint32_t> reopened;
  deferred.clear(), reopened.clear();
  size_t next_reopened = 0;
  uint32_t cluster = 0;
  const uint32_t* cluster_end = cluster_triangles.empty() ? end : indices + 3 * size_t(cluster_triangles[0]);
  while (out != end) {
    if (out == cluster_end) {  // the counts add up to T (the caller checked): a next cluster exists
      cluster_end += 3 * size_t(cluster_triangles[++cluster]);
      Front::reopen(front, cluster, deferred, reopened, next_reopened);
    }
    const uint32_t gate = front.next_gate(reopened, next_reopened, e);
    if (gate == front.size()) {
      uint32_t corner[3];
      for (int k = 0; k < 3; ++k) {
        const uint64_t r = refs.varint();
        if (r == 0) {
          if (next == V) fail("more vertices than the node holds");
          const uint32_t from = k > 0 ? corner[k - 1] : next > 0 ? next - 1 : V;
          predictors[3 * next] = predictors[3 * next + 1] = predictors[3 * next + 2] = from;
          corner[k] = next++;
        } else {
          if (r > next) fail("reference to a vertex not decoded yet");
          corner[k] = next - uint32_t(r);
        }
      }
      front.start(corner[0], corner[1], corner[2]);
      out[0] = corner[0], out[1] = corner[1], out[2] = corner[2];
      out += 3;
      continue;
    }
    if (symbol == symbols_end) fail("symbols end early");
    const Front::Edge& g = front.edge(gate);
    const uint32_t a = g.a, b = g.b;
    uint32_t c;
    switch (*symbol++) {
      case kVertex:
        if (next == V) fail("more vertices than the node holds");
        c = next++;
        predictors[3 * c] = a, predictors[3 * c + 1] = b, predictors[3 * c + 2] = g.o;
        front.attach(gate, c);
        break;
      case kLeft:
        c = front.left(gate);
        if (c == kNone) fail("left turn in a loop of 2");
        front.close_left(gate);
        break;
      case kRight:
        c = front.right(gate);
        if (c == kNone) fail("right turn in a loop of 2");
        front.close_right(gate);
        break;
      case kEnd:
        if (!front.closes(gate)) fail("end of a loop that is not 3 edges");
        c = front.left(gate);
        front.close_loop(gate);
        break;
      case kSplit: {
        const uint64_t r = refs.varint();
        if (r >= next) fail("reference to a vertex not decoded yet");
        c = next - 1 - uint32_t(r);
        front.attach(gate, c);
        break;
      }
      case kBoundary:
        front.done(gate);
        continue;
      default:
        if (symbol[-1] < kDefer || symbol[-1] >= kDefer + kDeferClusters) fail("unknown symbol");
        front.defer(gate, cluster + 1 + (symbol[-1] - kDefer), deferred);
        continue;
    }
    out[0] = b, out[1] = a, out[2] = c;
    out += 3;
  }
  if (symbol != symbols_end) fail("symbols left over");
  if (!refs.at_end()) fail("references left over");
  for (; next < V; ++next) {
    const uint32_t from = next > 0 ? next - 1 : V;
    predictors[3 * next] = predictors[3 * next + 1] = predictors[3 * next + 2] = from;
  }
}

}  // namespace lodstream::package
