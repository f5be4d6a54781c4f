#include "solver/colour_flow.hpp"

#include "solver/graph_solver.hpp"

#include <algorithm>

namespace cairn {

namespace {

// Work in row groups: a batch visit costs about kGroupsPerBatchVisit of
// them (graph_solver.hpp).
constexpr std::int32_t kBatchWork = kGroupsPerBatchVisit;
constexpr std::int32_t kGroupWork = 1;

// What an item that waits for another thread's item loses, in the plan's
// model: about one batch visit, the time for the other core's release to
// be seen and its bodies' cache lines to move over. Measured on the 2-core
// Xeon of docs/performance.md: pyramid-20's colours, split evenly with a
// wait before nearly every run of a colour, made its solve 20% slower on
// two threads than on one, while the plan without this cost promised
// 1.34x; with it, the plans of pyramid-40 and the 5,050-box pyramid
// promised 1.3x and 1.8x, and their solves gained 1.2x and 1.55x.
constexpr std::int32_t kHandover = kBatchWork;

// The largest colour, in items, that the plan also tries whole on one
// thread. Trying single items whole gave the shortest planned critical
// paths (pyramid-40: 2,208 eighths of a visit, against 2,392 trying none,
// 2,280 up to two items and 2,600 every colour; the 5,050-box pyramid:
// 8,984 against 9,168, 9,056 and 9,376), and pyramid-40's solve on two
// threads ran 6.1 ms a step against 6.45 trying up to two; a larger
// colour is better split.
constexpr std::int32_t kMaxWhole = 1;

}  // namespace

ColourFlow& ColourFlow::operator=(const ColourFlow& o) {
  if (this == &o) return *this;
  threads_ = o.threads_;
  planned_ = o.planned_;
  thread_begin_ = o.thread_begin_;
  items_ = o.items_;
  need_ = o.need_;
  prev_need_ = o.prev_need_;
  own_prev_begin_ = o.own_prev_begin_;
  own_prev_ = o.own_prev_;
  ran_.assign(o.ran_.size(), 0);
  tally_.assign(o.tally_.size(), Tally{});
  progress_size_ = o.progress_size_;
  progress_ = progress_size_ > 0 ? std::make_unique<Progress[]>(static_cast<size_t>(progress_size_)) : nullptr;
  return *this;
}

void appendItemBodies(const GraphProblem& p, FlowItem it, int dynamic_end, std::vector<std::int32_t>& out) {
  const auto dynamic = [&](std::int32_t b) { return b > 0 && b < dynamic_end; };
  const GraphColour& gc = p.colours[static_cast<size_t>(it.colour)];
  const std::int32_t groups = gc.group_end - gc.group_begin;
  if (it.item < groups) {
    const RowGroup& g = p.groups[static_cast<size_t>(gc.group_begin + it.item)];
    for (std::int32_t r = g.begin; r < g.end; ++r) {
      const ConstraintRow& row = p.rows[static_cast<size_t>(r)];
      if (dynamic(row.body_a)) out.push_back(row.body_a);
      if (dynamic(row.body_b)) out.push_back(row.body_b);
    }
    return;
  }
  const ContactBatch& b = p.batches[static_cast<size_t>(gc.batch_begin + it.item - groups)];
  for (int l = 0; l < kBatchLanes; ++l) {
    if (b.count[l] == 0) continue;
    if (dynamic(b.body_a[l])) out.push_back(b.body_a[l]);
    if (dynamic(b.body_b[l])) out.push_back(b.body_b[l]);
  }
}

// The work and dynamic bodies of each item of a colour.
void ColourFlow::colourItems(const GraphProblem& p, std::int32_t colour, int dynamic_end) {
  const GraphColour& gc = p.colours[static_cast<size_t>(colour)];
  const std::int32_t groups = gc.group_end - gc.group_begin;
  item_work_.clear();
  item_body_begin_.assign(1, 0);
  item_bodies_.clear();
  for (std::int32_t i = 0; i < groups + gc.batch_end - gc.batch_begin; ++i) {
    appendItemBodies(p, {colour, i}, dynamic_end, item_bodies_);
    item_work_.push_back(i < groups ? kGroupWork : kBatchWork);
    item_body_begin_.push_back(static_cast<std::int32_t>(item_bodies_.size()));
  }
}

// When the colour's item `item` could start on `thread` in the plan's
// model, its thread aside: when the items that last touched its bodies are
// done (plus a handover from another thread).
std::int64_t ColourFlow::ready(std::int32_t item, std::int32_t thread) const {
  std::int64_t at = 0;
  for (const std::int32_t b : bodiesOf(item)) {
    const std::int32_t j = last_[static_cast<size_t>(b)];
    if (j < 0) continue;
    const Planned& s = sequence_[static_cast<size_t>(j)];
    at = std::max(at, s.finish + (s.thread == thread ? 0 : kHandover));
  }
  return at;
}

// When the colour ends with these runs, and (through `sum`) the sum of the
// runs' ends, the tie-break: the same end with less of every thread's time.
std::int64_t ColourFlow::evaluate(const std::vector<Run>& runs, std::int64_t& sum) const {
  std::int64_t end = 0;
  sum = 0;
  for (const Run& r : runs) {
    std::int64_t t = free_[static_cast<size_t>(r.thread)];
    for (std::int32_t n = 0; n < r.end - r.begin; ++n) {
      const std::int32_t i = visit(r, n);
      t = std::max(t, ready(i, r.thread)) + item_work_[static_cast<size_t>(i)];
    }
    end = std::max(end, t);
    sum += t;
  }
  return end;
}

void ColourFlow::commit(std::int32_t colour, const std::vector<Run>& runs) {
  const size_t T = static_cast<size_t>(threads_);
  const size_t first = sequence_.size();
  for (const Run& r : runs) {
    const size_t t = static_cast<size_t>(r.thread);
    for (std::int32_t n = 0; n < r.end - r.begin; ++n) {
      const std::int32_t i = visit(r, n);
      Planned s;
      s.item = {colour, i};
      s.thread = r.thread;
      s.at = count_[t]++;
      s.finish = std::max(free_[t], ready(i, r.thread)) + item_work_[static_cast<size_t>(i)];
      // Per other thread, the last of its items to touch one of this
      // item's bodies: waiting for that one is enough, a thread finishes
      // its items in order.
      need_sequence_.resize(need_sequence_.size() + T, 0);
      std::int32_t* need = need_sequence_.data() + need_sequence_.size() - T;
      for (const std::int32_t b : bodiesOf(i)) {
        const std::int32_t j = last_[static_cast<size_t>(b)];
        if (j < 0) continue;
        const Planned& dep = sequence_[static_cast<size_t>(j)];
        if (dep.thread != r.thread) need[dep.thread] = std::max(need[dep.thread], dep.at + 1);
      }
      free_[t] = s.finish;
      load_[t] += item_work_[static_cast<size_t>(i)];
      sequence_.push_back(s);
      const auto own_first = static_cast<std::ptrdiff_t>(own_prev_sequence_.size());
      for (const std::int32_t b : bodiesOf(i)) {
        sequence_bodies_.push_back(b);
        std::int32_t& last_here = last_at_[static_cast<size_t>(b) * T + t];
        if (last_here >= 0 && std::find(own_prev_sequence_.begin() + own_first, own_prev_sequence_.end(), last_here) ==
                                  own_prev_sequence_.end())
          own_prev_sequence_.push_back(last_here);
        last_here = s.at;  // a thread's items come in order
      }
      own_prev_sequence_begin_.push_back(static_cast<std::int32_t>(own_prev_sequence_.size()));
      sequence_body_begin_.push_back(static_cast<std::int32_t>(sequence_bodies_.size()));
    }
  }
  // The items of a colour share no body, so their marks can go in after
  // all of them have read theirs.
  for (size_t q = first; q < sequence_.size(); ++q) {
    for (const std::int32_t b : bodiesOf(sequence_[q].item.item))
      last_[static_cast<size_t>(b)] = static_cast<std::int32_t>(q);
  }
}

bool ColourFlow::plan(const GraphProblem& p, int threads, int dynamic_end, double min_saving) {
  threads_ = 0;
  planned_ = true;
  if (threads < 2 || p.colours.empty()) return false;
  threads_ = threads;
  const size_t T = static_cast<size_t>(threads);
  sequence_.clear();
  need_sequence_.clear();
  own_prev_sequence_.clear();
  own_prev_sequence_begin_.assign(1, 0);
  count_.assign(T, 0);
  load_.assign(T, 0);
  free_.assign(T, 0);
  last_.assign(static_cast<size_t>(std::max(dynamic_end, 1)), -1);
  last_at_.assign(static_cast<size_t>(std::max(dynamic_end, 1)) * T, -1);
  sequence_bodies_.clear();
  sequence_body_begin_.assign(1, 0);

  // Who sweeps what, colour by colour, each colour cut the way that ends it
  // soonest in the plan's model (list scheduling): one contiguous run of
  // its items per thread, cut so that each thread's work so far stays
  // even, or, for a colour of a single item, the whole colour on one
  // thread (the one that holds its bodies: no handover).
  std::int64_t total = 0;
  for (size_t c = 0; c < p.colours.size(); ++c) {
    colourItems(p, static_cast<std::int32_t>(c), dynamic_end);
    const std::int32_t items = static_cast<std::int32_t>(item_work_.size());
    if (items == 0) continue;
    std::int64_t after = total;
    for (const std::int32_t w : item_work_) after += w;
    runs_.clear();
    size_t t = 0;
    std::int64_t load = load_[0];
    for (std::int32_t i = 0; i < items; ++i) {
      const std::int32_t w = item_work_[static_cast<size_t>(i)];
      // Move on while this thread would pass an even share of the work
      // done by the end of the colour.
      while (t + 1 < T && (load + w) * threads > after) load = load_[++t];
      if (runs_.empty() || runs_.back().thread != static_cast<std::int32_t>(t))
        runs_.push_back({static_cast<std::int32_t>(t), i, i});
      runs_.back().end = i + 1;
      load += w;
    }
    std::int64_t best_sum = 0;
    std::int64_t best_end = evaluate(runs_, best_sum);
    best_ = runs_;
    for (std::int32_t u = 0; u < threads && items <= kMaxWhole; ++u) {
      runs_.assign(1, {u, 0, items});
      std::int64_t sum = 0;
      const std::int64_t end = evaluate(runs_, sum);
      if (end < best_end || (end == best_end && sum < best_sum)) {
        best_end = end;
        best_sum = sum;
        best_ = runs_;
      }
    }
    commit(static_cast<std::int32_t>(c), best_);
    total = after;
  }

  std::int64_t makespan = 0;
  for (const std::int64_t f : free_) makespan = std::max(makespan, f);
  if (static_cast<double>(total - makespan) < min_saving * kBatchWork) {
    threads_ = 0;
    return false;
  }

  // Each thread's items together, in the order it visits them.
  thread_begin_.assign(T + 1, 0);
  for (size_t t = 0; t < T; ++t) thread_begin_[t + 1] = thread_begin_[t] + count_[t];
  items_.resize(sequence_.size());
  need_.resize(need_sequence_.size());
  prev_need_.resize(need_sequence_.size());
  ran_.assign(sequence_.size() * kMaxOverlappedPasses, 0);
  tally_.assign(T, Tally{});
  // The own items before each, gathered in the threads' order.
  own_prev_begin_.assign(sequence_.size() + 1, 0);
  for (size_t q = 0; q < sequence_.size(); ++q) {
    const Planned& s = sequence_[q];
    own_prev_begin_[static_cast<size_t>(thread_begin_[static_cast<size_t>(s.thread)] + s.at) + 1] =
        own_prev_sequence_begin_[q + 1] - own_prev_sequence_begin_[q];
  }
  for (size_t k = 0; k < sequence_.size(); ++k) own_prev_begin_[k + 1] += own_prev_begin_[k];
  own_prev_.resize(own_prev_sequence_.size());
  for (size_t q = 0; q < sequence_.size(); ++q) {
    const Planned& s = sequence_[q];
    const size_t k = static_cast<size_t>(thread_begin_[static_cast<size_t>(s.thread)] + s.at);
    items_[k] = s.item;
    std::copy(own_prev_sequence_.begin() + own_prev_sequence_begin_[q], own_prev_sequence_.begin() + own_prev_sequence_begin_[q + 1],
              own_prev_.begin() + own_prev_begin_[k]);
    std::copy_n(need_sequence_.begin() + static_cast<std::ptrdiff_t>(q * T), T,
                need_.begin() + static_cast<std::ptrdiff_t>(k * T));
    // The pass before, for interleaved passes: per thread, its last item
    // over the whole pass to touch one of this item's bodies.
    const std::int32_t begin = sequence_body_begin_[q];
    passBeforeNeed({sequence_bodies_.data() + begin, static_cast<size_t>(sequence_body_begin_[q + 1] - begin)},
                   last_at_.data(), T, static_cast<size_t>(s.thread), s.at, prev_need_.data() + k * T);
  }
  const int progress = kMaxOverlappedPasses * threads;
  if (progress_size_ < progress) {
    progress_ = std::make_unique<Progress[]>(static_cast<size_t>(progress));
    progress_size_ = progress;
  }
  return true;
}

}  // namespace cairn
