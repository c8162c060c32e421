// The monitor's time line (a double, s) from the stamps of several sources whose clocks may
// differ. Pure: no node, no master.
//
// The first state ever received sets the line's zero (its epoch). Each source (a topic and the
// node publishing on it) has an offset, zero unless its clock is found to differ:
//  - a source whose own stamps go back by more than ~clock_jump_back (a bag played with
//    --loop, a simulator restarted) restarts the line from that stamp: every track is reset;
//  - a source whose stamps lie more than ~clock_jump_back behind the line while its own stamps
//    did not go back (a second machine whose clock is 5 s behind, or a source that joins after
//    another one moved the line ahead) is shifted onto the line: its offset becomes the lag,
//    said once in a warning that names it and the source that set the line. Instants across two
//    such sources are then only as good as the alignment (about one message period).
// Differences are taken in integer nanoseconds: no stamp can make the arithmetic throw (as
// ros::Duration does beyond 2^31 s) or lose its nanoseconds.
#pragma once

#include <ros/time.h>

#include <cstdint>
#include <map>
#include <string>

namespace collision_response {

class TimeLine {
 public:
  /// `clock_jump_back`, s: how far a stamp may lag before it is a jump or an offset.
  explicit TimeLine(double clock_jump_back);

  enum class Event {
    kNone,
    kStarted,       ///< the first stamp: the line starts here
    kJumpedBack,    ///< the source's own clock went back: the line restarts at the stamp
    kOffsetChanged  ///< the source was shifted onto the line (offset())
  };
  struct Placed {
    double time = 0.0;  ///< s on the line
    Event event = Event::kNone;
  };

  /// Places `stamp`, from `source`, on the line; `now` is the monitor's time (s on the line,
  /// meaningful once started). A kJumpedBack asks the caller to reset the monitor.
  Placed place(const std::string& source, const ros::Time& stamp, double now);

  /// The stamp of an instant of the line, in the clock of the source that started it; false
  /// when the instant is not a valid ros::Time (not finite, before 0 or past 2^32 s).
  bool stampOf(double time, ros::Time& stamp) const;

  bool started() const { return started_; }
  /// s the source's stamps are shifted by (0: none, or an unknown source).
  double offset(const std::string& source) const;
  /// The source whose stamps started the line.
  const std::string& firstSource() const { return first_source_; }
  /// The sources seen since the line started and their offsets (s).
  std::map<std::string, double> offsets() const;

  /// Forgets every source and the epoch.
  void reset();

  /// At most this many sources are remembered; the one heard from least recently is forgotten
  /// (a source comes back as a new one): a bound whatever publishers come and go.
  static constexpr std::size_t kMaxSources = 64;

 private:
  struct Source {
    std::int64_t offset = 0;      ///< ns added to its stamps
    std::int64_t last_stamp = 0;  ///< ns, its newest stamp
    std::uint64_t heard = 0;      ///< when it was last heard (a counter)
  };
  std::int64_t jump_ns_;
  bool started_ = false;
  std::int64_t epoch_ = 0;  ///< ns
  std::string first_source_;
  std::map<std::string, Source> sources_;
  std::uint64_t heard_ = 0;
};

}  // namespace collision_response
