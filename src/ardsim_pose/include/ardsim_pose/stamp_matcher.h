// Matches messages of several streams by exact stamp (the evaluator's estimate and its two truth states),
// each waiting in a bounded buffer for the others whichever arrives first. ROS-free: stamps are nanoseconds.
//
// Time going back (a bag played again, a simulation restarted) starts a new time line. The one before is kept
// for its late messages, which do come: the truth of a replayed bag's next pass reaches the evaluator before
// the estimates of the last frames of the pass before, which wait in the pose node's queue. A late message is
// told apart by its stamp, more than restart_time_jump beyond the newest of the new line; once the new line
// comes that close to the old one's stamps the two cannot be told apart, and the old one is dropped.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <tuple>
#include <utility>

namespace ardsim_pose {

template <typename... Messages>
class StampMatcher {
 public:
  using Stamp = std::int64_t;  // nanoseconds
  using Match = std::tuple<Messages...>;

  struct Added {
    std::optional<Match> match;  // every stream's message of this stamp, now all in
    // Set where this message started a new time line: the last stamp matched before it.
    std::optional<Stamp> went_back_from;
  };

  StampMatcher(std::size_t buffer_size, Stamp restart_time_jump)
      : buffer_size_(buffer_size), restart_time_jump_(restart_time_jump) {}

  template <std::size_t I>
  Added add(Stamp stamp, std::tuple_element_t<I, Match> message) {
    Added added;
    if (current_.last_matched && stamp < *current_.last_matched - restart_time_jump_) {
      added.went_back_from = current_.last_matched;
      previous_ = std::move(current_);
      current_ = TimeLine{};
    }
    TimeLine& line = isLate(stamp) ? *previous_ : current_;
    auto& waiting = std::get<I>(line.waiting);
    waiting[stamp] = std::move(message);
    while (waiting.size() > buffer_size_) waiting.erase(waiting.begin());
    if (!line.newest || stamp > *line.newest) line.newest = stamp;
    if (previous_ && current_.newest && *current_.newest + restart_time_jump_ >= *previous_->newest)
      previous_.reset();
    added.match = line.complete(stamp, std::index_sequence_for<Messages...>{});
    return added;
  }

  // Messages waiting in the current time line and in the one before, all streams together.
  std::size_t waiting() const { return current_.size() + (previous_ ? previous_->size() : 0); }

 private:
  struct TimeLine {
    std::tuple<std::map<Stamp, Messages>...> waiting;
    std::optional<Stamp> newest;        // newest stamp added
    std::optional<Stamp> last_matched;  // stamp of the last match

    std::size_t size() const {
      return std::apply([](const auto&... maps) { return (maps.size() + ... + 0); }, waiting);
    }

    template <std::size_t... Is>
    std::optional<Match> complete(Stamp stamp, std::index_sequence<Is...>) {
      if (!(std::get<Is>(waiting).count(stamp) && ...)) return std::nullopt;
      Match match(std::move(std::get<Is>(waiting)[stamp])...);
      // Streams come in stamp order: what waits from before this stamp will not be completed.
      (std::get<Is>(waiting).erase(std::get<Is>(waiting).begin(), std::get<Is>(waiting).upper_bound(stamp)),
       ...);
      last_matched = stamp;
      return match;
    }
  };

  bool isLate(Stamp stamp) const {
    return previous_ && current_.newest && stamp > *current_.newest + restart_time_jump_;
  }

  std::size_t buffer_size_;
  Stamp restart_time_jump_;
  TimeLine current_;
  std::optional<TimeLine> previous_;
};

}  // namespace ardsim_pose
