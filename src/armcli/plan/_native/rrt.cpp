// RRT-Connect (Kuffner and LaValle 2000) over the compiled checker, with seeded restarts.
//
// Two trees grow from the start and the goal; each round one tree extends toward a random
// state (or, with probability goal_bias, toward the other tree's root) by at most `range`,
// and the other tree then greedily connects toward the new node. Every edge is checked by
// Work::motion_free at `step`. An attempt that has grown `attempt_nodes` nodes gives way to
// the next attempt with the next seed (a search stuck in the wrong pocket of a narrow passage
// rarely gets out, a fresh one often finds the way: restarts cut the heavy tail of the time
// to solve). Attempts run on `threads` threads at once; the path returned is always the one
// of the lowest-numbered attempt that succeeds, so a seed gives the same path whatever the
// number of threads, whenever the search ends before the timeout.
//
// Lazy edges (lazy_step > step): the trees grow with edges checked every lazy_step only;
// when they meet, each edge of the path not yet checked at `step` is checked then, and an
// edge that fails takes its child's subtree out of its tree (as Lazy PRM drops an edge),
// and the search goes on. The path returned has every edge checked at `step`, as without
// laziness; most tree edges, which no path uses, are checked at the coarse step only.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cmath>
#include <map>
#include <mutex>
#include <thread>

#include "core.hpp"

namespace armcli_plan {

namespace {

using Clock = std::chrono::steady_clock;
constexpr int BRIDGE_TRIES = 10;  // bridge tests per sample before a uniform one

// xoshiro256** seeded by splitmix64: the same numbers on every platform.
class Rng {
 public:
  explicit Rng(uint64_t seed) {
    for (auto& x : s_) {
      seed += 0x9e3779b97f4a7c15ULL;
      uint64_t z = seed;
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      x = z ^ (z >> 31);
    }
  }
  uint64_t next() {
    const uint64_t out = rotl(s_[1] * 5, 7) * 9, t = s_[1] << 17;
    s_[2] ^= s_[0], s_[3] ^= s_[1], s_[1] ^= s_[2], s_[0] ^= s_[3];
    s_[2] ^= t, s_[3] = rotl(s_[3], 45);
    return out;
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double normal() {  // Box-Muller
    const double u = 1.0 - uniform(), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(6.283185307179586 * v);
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t s_[4];
};

enum Grow { TRAPPED, ADVANCED, REACHED };

// A tree of states. The nearest-neighbour search is a brute-force scan over the nodes kept
// coordinate by coordinate in single precision, which the compiler vectorises: on trees of
// the sizes RRT-Connect grows here (10^3 - 10^4 nodes) it beats a k-d tree in 7 dimensions.
struct Tree {
  int n = 0;
  std::vector<double> x;  // node k at x[k * n]
  std::vector<int> parent;
  std::vector<char> checked;  // the edge to the parent was checked at the fine step
  std::vector<char> dead;     // cut off with a subtree whose root edge failed
  std::vector<std::vector<float>> axis;  // axis[i][k]: coordinate i of node k
  std::vector<float> dist;

  size_t size() const { return parent.size(); }
  const double* node(size_t k) const { return x.data() + k * n; }

  void add(const double* q, int up, bool fine) {
    x.insert(x.end(), q, q + n);
    parent.push_back(up);
    checked.push_back(fine);
    dead.push_back(0);
    axis.resize(n);
    for (int i = 0; i < n; ++i) axis[i].push_back(static_cast<float>(q[i]));
  }

  size_t nearest(const double* q) {
    const size_t N = size();
    dist.assign(N, 0.0f);
    float* d = dist.data();
    for (int i = 0; i < n; ++i) {
      const float qi = static_cast<float>(q[i]);
      const float* c = axis[i].data();
      for (size_t k = 0; k < N; ++k) d[k] += (c[k] - qi) * (c[k] - qi);
    }
    return static_cast<size_t>(std::min_element(dist.begin(), dist.end()) - dist.begin());
  }

  // Node k and its descendants out of the search (children come after their parents).
  void cut(size_t k) {
    dead[k] = 1;
    for (size_t j = k + 1; j < size(); ++j)
      if (!dead[j] && dead[parent[j]]) dead[j] = 1;
    for (size_t j = k; j < size(); ++j)
      if (dead[j])
        for (int i = 0; i < n; ++i) axis[i][j] = FAR;  // never the nearest again
  }

  static constexpr float FAR = 1e18f;  // its squared distance overflows to infinity
};

class Attempt {
 public:
  Attempt(Work& w, const PlanOptions& o, uint64_t seed)
      : w_(w), o_(o), rng_(seed), n_(w.s.n), target_(n_), grown_(n_), end_a_(n_), end_b_(n_) {}

  // The path, or empty when the attempt gave up (node budget) or was stopped.
  RMat run(const Vec& start, const Vec& goal, const std::atomic<bool>& stop, Clock::time_point end,
           long& nodes) {
    Tree t[2];
    t[0].n = t[1].n = n_;
    t[0].add(start.data(), -1, true);
    t[1].add(goal.data(), -1, true);
    int a = 0;
    for (long round = 0;; ++round) {
      if ((round & 15) == 0 && (stop.load(std::memory_order_relaxed) || Clock::now() > end))
        return {};
      if (static_cast<long>(t[0].size() + t[1].size()) > o_.attempt_nodes) return {};
      sample(t[1 - a]);
      size_t added;
      if (grow(t[a], target_.data(), added) != TRAPPED) {
        const Vec x_new = Eigen::Map<const Vec>(t[a].node(added), n_);
        size_t met;
        Grow g;
        do g = grow(t[1 - a], x_new.data(), met);
        while (g == ADVANCED && !stop.load(std::memory_order_relaxed));
        if (g == REACHED) {
          const size_t at0 = a == 0 ? added : met, at1 = a == 0 ? met : added;
          if (verified(t[0], at0) && verified(t[1], at1)) {
            nodes += static_cast<long>(t[0].size() + t[1].size());
            return join(t[0], at0, t[1], at1);
          }
        }
      }
      a = 1 - a;
    }
  }

 private:
  void sample(const Tree& other) {
    const double u = rng_.uniform();
    if (u < o_.goal_bias) {
      target_ = Eigen::Map<const Vec>(other.node(0), n_);
      return;
    }
    if (u < o_.goal_bias + o_.bridge && bridge()) return;
    uniform(target_);
  }

  void uniform(Vec& x) {
    for (int i = 0; i < n_; ++i)
      x[i] = w_.s.lower[i] + rng_.uniform() * (w_.s.upper[i] - w_.s.lower[i]);
  }

  // The bridge test (Hsu et al. 2003): two states in collision near each other whose
  // midpoint is free; such midpoints lie in narrow passages.
  bool bridge() {
    for (int tries = 0; tries < BRIDGE_TRIES; ++tries) {
      uniform(end_a_);
      if (w_.free(end_a_.data())) continue;
      for (int i = 0; i < n_; ++i)
        end_b_[i] = std::clamp(end_a_[i] + o_.bridge_sigma * rng_.normal(), w_.s.lower[i],
                               w_.s.upper[i]);
      if (w_.free(end_b_.data())) continue;
      target_ = 0.5 * (end_a_ + end_b_);
      if (w_.free(target_.data())) return true;
    }
    return false;
  }

  // Whether every edge from node k to the root is free at the fine step; the first that
  // is not (from the root down) is cut with its subtree.
  bool verified(Tree& t, size_t k) {
    std::vector<size_t> chain;
    for (int j = static_cast<int>(k); j > 0; j = t.parent[j]) chain.push_back(j);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const size_t j = *it;
      if (t.checked[j]) continue;
      if (!w_.motion_free(t.node(t.parent[j]), t.node(j), o_.step)) {
        t.cut(j);
        return false;
      }
      t.checked[j] = 1;
    }
    return true;
  }

  // Extend `t` toward `q` by at most `range`; `added`: the node reached or added.
  Grow grow(Tree& t, const double* q, size_t& added) {
    const size_t k = t.nearest(q);
    const double* from = t.node(k);
    double d = 0.0;
    for (int i = 0; i < n_; ++i) d += (q[i] - from[i]) * (q[i] - from[i]);
    d = std::sqrt(d);
    if (d == 0.0) {
      added = k;
      return REACHED;
    }
    const bool reach = d <= o_.range;
    const double u = reach ? 1.0 : o_.range / d;
    for (int i = 0; i < n_; ++i) grown_[i] = reach ? q[i] : from[i] + (q[i] - from[i]) * u;
    const bool lazy = o_.lazy_step > o_.step;
    if (!w_.motion_free(from, grown_.data(), lazy ? o_.lazy_step : o_.step)) return TRAPPED;
    t.add(grown_.data(), static_cast<int>(k), !lazy);
    added = t.size() - 1;
    return reach ? REACHED : ADVANCED;
  }

  // start root ... a, then b ... goal root (a and b hold the same state when they met).
  RMat join(const Tree& ts, size_t a, const Tree& tg, size_t b) const {
    std::vector<const double*> rows;
    for (int k = static_cast<int>(a); k >= 0; k = ts.parent[k]) rows.push_back(ts.node(k));
    std::reverse(rows.begin(), rows.end());
    int k = static_cast<int>(b);
    if (std::equal(tg.node(k), tg.node(k) + n_, rows.back())) k = tg.parent[k];
    for (; k >= 0; k = tg.parent[k]) rows.push_back(tg.node(k));
    RMat out(rows.size(), n_);
    for (size_t r = 0; r < rows.size(); ++r) out.row(r) = Eigen::Map<const Vec>(rows[r], n_);
    return out;
  }

  Work& w_;
  const PlanOptions& o_;
  Rng rng_;
  int n_;
  Vec target_, grown_, end_a_, end_b_;
};

uint64_t attempt_seed(uint64_t seed, int attempt) {
  return seed * 0x100000001b3ULL + static_cast<uint64_t>(attempt) * 0x9e3779b97f4a7c15ULL;
}

}  // namespace

RMat rrt_connect(const Scene& s, const Vec& start, const Vec& goal, const PlanOptions& o,
                 PlanStats& stats) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(o.timeout));
  std::atomic<int> next{0}, best{INT_MAX};
  std::atomic<long> states{0}, nodes{0};
  std::atomic<bool> timed_out{false};
  std::mutex lock;
  std::map<int, RMat> found;
  std::vector<std::unique_ptr<std::atomic<bool>>> stops;
  std::mutex stops_lock;
  auto worker = [&]() {
    Work w(s);
    for (;;) {
      const int k = next.fetch_add(1);
      if (k > best.load() || Clock::now() > end) break;
      auto stop = std::make_unique<std::atomic<bool>>(false);
      std::atomic<bool>* flag = stop.get();
      {
        std::lock_guard<std::mutex> g(stops_lock);
        stops.resize(std::max<size_t>(stops.size(), k + 1));
        stops[k] = std::move(stop);
        if (k > best.load()) flag->store(true);
      }
      long grown = 0;
      Attempt attempt(w, o, attempt_seed(o.seed, k));
      RMat path = attempt.run(start, goal, *flag, end, grown);
      nodes += grown;
      if (Clock::now() > end && path.rows() == 0) timed_out = true;
      if (path.rows() == 0) continue;
      std::lock_guard<std::mutex> g(lock);
      found[k] = std::move(path);
      int cur = best.load();
      while (k < cur && !best.compare_exchange_weak(cur, k)) {
      }
      std::lock_guard<std::mutex> g2(stops_lock);
      for (size_t j = k + 1; j < stops.size(); ++j)
        if (stops[j]) stops[j]->store(true);  // later attempts cannot win any more
    }
    states += w.states;
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::max(1, o.threads); ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  stats.states = states.load();
  stats.nodes = nodes.load();
  stats.timed_out = timed_out.load();
  if (found.empty()) return {};
  stats.attempt = found.begin()->first;
  return found.begin()->second;
}

namespace {

RMat greedy(Work& w, const RMat& path, double step) {
  std::vector<int> keep{0};
  int i = 0;
  const int last = static_cast<int>(path.rows()) - 1;
  while (i < last) {
    int j = last;
    while (j > i + 1 && !w.motion_free(path.row(i).data(), path.row(j).data(), step)) --j;
    keep.push_back(j);
    i = j;
  }
  RMat out(keep.size(), path.cols());
  for (size_t r = 0; r < keep.size(); ++r) out.row(r) = path.row(keep[r]);
  return out;
}

}  // namespace

RMat shortcut(Work& w, const RMat& input, double step, uint64_t seed, int tries, int patience) {
  RMat path = greedy(w, input, step);
  Rng rng(seed ^ 0x5ca1ab1e5ca1ab1eULL);
  int misses = 0;
  const long n = path.cols();
  Vec p1(n), p2(n);
  for (int t = 0; t < tries; ++t) {
    if (path.rows() < 3 || misses >= patience) break;
    std::vector<double> cum{0.0};
    for (long r = 1; r < path.rows(); ++r)
      cum.push_back(cum.back() + (path.row(r) - path.row(r - 1)).norm());
    double d1 = rng.uniform() * cum.back(), d2 = rng.uniform() * cum.back();
    if (d2 < d1) std::swap(d1, d2);
    auto at = [&](double d, Vec& p) {
      long k = std::upper_bound(cum.begin(), cum.end(), d) - cum.begin() - 1;
      k = std::clamp<long>(k, 0, path.rows() - 2);
      const double seg = cum[k + 1] - cum[k];
      const double u = seg <= 0.0 ? 0.0 : (d - cum[k]) / seg;
      p = path.row(k).transpose() + (path.row(k + 1) - path.row(k)).transpose() * u;
      return k;
    };
    const long k1 = at(d1, p1), k2 = at(d2, p2);
    if (k1 == k2 || !w.motion_free(p1.data(), p2.data(), step)) {
      ++misses;
      continue;
    }
    misses = 0;
    std::vector<Vec> rows;
    for (long r = 0; r <= k1; ++r) rows.push_back(path.row(r).transpose());
    rows.push_back(p1);
    rows.push_back(p2);
    for (long r = k2 + 1; r < path.rows(); ++r) rows.push_back(path.row(r).transpose());
    std::vector<Vec> kept{rows[0]};
    for (size_t r = 1; r < rows.size(); ++r)
      if (rows[r] != kept.back()) kept.push_back(rows[r]);
    path.resize(kept.size(), n);
    for (size_t r = 0; r < kept.size(); ++r) path.row(r) = kept[r].transpose();
  }
  return greedy(w, path, step);
}

}  // namespace armcli_plan
