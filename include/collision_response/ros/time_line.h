// The monitor's time line (a double, s) from the stamps of several sources whose clocks may
// differ. Pure: no node, no master.
//
// The line keeps the node's clock (`clock`: ros::Time::now() when a message is processed;
// zero when not known yet, sim time before the first /clock). Each source (a topic and the node
// publishing on it) has one clock, or two when it interleaves two; each clock has an offset
// (ns added to its stamps), zero when its stamps agree with the node's clock:
//  - a new source whose stamps agree with the node's clock (within ~clock_jump_back) keeps
//    offset zero: nothing another source sends moves it (a source sending one state stamped
//    now + 299 s does not shift the good ones: it is the odd one that gets an offset);
//  - a new source whose stamps differ from the node's clock by more (a second machine whose
//    clock is 5 s behind, a bag played without use_sim_time) takes the offset of a clock
//    another source keeps if its stamp lands where that source is now (two topics of one
//    machine or one bag: exact across them), else one that places it at the line's present;
//    said once, in a warning that names it. Instants across sources of different clocks are
//    then only as good as that alignment (about one message period). Without the node's clock,
//    a new source keeps offset zero unless it lags the line by more than ~clock_jump_back;
//  - a stamp that, on its source's clock, lands more than ~clock_jump_back ahead of the line's
//    present (judged only with the node's clock) is placed at the line's present on a clock of
//    its own (one odd stamp, a publisher interleaving two clocks, or a source whose stamps
//    leapt ahead): the source's other clock and every other source are not moved;
//  - a stamp that goes back by more than ~clock_jump_back on its source's clock (one heard
//    more than once, or any without the node's clock; else it is a clock of its own) is held: if
//    the source's next message continues from it (rosbag play --loop, a simulator restarted),
//    every track is reset and the line restarts at the held stamp (the held states enter the
//    new line); if the next one continues the clock before, the held states are dropped,
//    naming the source, and should the held clock go on, interleaved with the other one, it
//    becomes the source's second clock, placed at the line's present;
//  - no state is placed ahead of the line's present (judged only with a node's clock that ran
//    since the line's last placement): the monitor cannot step back, so a state placed there
//    would put every other source's next states in its past. A stamp of the node's clock a
//    little ahead of it (another machine's, within ~clock_jump_back) is placed at the present;
//    a clock of its own that runs ahead (a bag played faster than it was recorded without
//    use_sim_time, past ~clock_jump_back ahead and on a clock of its own from then on) is
//    placed at the present, its offset following, said only when it got that clock;
//  - a clock that lags the line's last instant by more than ~clock_jump_back while its stamps
//    go forward (a source that joins after another one moved the line ahead, a bag played
//    slower than it was recorded) is shifted onto the line's present, said when it leaves the
//    node's clock; "the line's last instant" is never past the present, whatever a source ahead
//    of the node's clock sent, so a source that keeps the node's clock (its messages' latency
//    below ~clock_jump_back) keeps its stamps.
// The line's present is the node's clock, on the line (epoch_ is line zero in it): no source
// moves it, however fast its clock runs; without a running node's clock, the line's last
// instant.
// An instant of the line has a stamp in each clock (stampOf): an impact is stamped in the clock
// of the states that produced it. Differences are taken in integer nanoseconds: no stamp can
// make the arithmetic throw (as ros::Duration does beyond 2^31 s) or lose its nanoseconds.
#pragma once

#include <ros/time.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace collision_response {

class TimeLine {
 public:
  /// `clock_jump_back`, s: how far a stamp may stray from its clock before it is a jump, an
  /// offset or a clock of its own.
  explicit TimeLine(double clock_jump_back);

  enum class Event {
    kNone,
    kStarted,        ///< the first stamp: the line starts here
    kJumpedBack,     ///< the source's clock went back, confirmed: the line restarts there
    kOffsetChanged,  ///< a new source off the node's clock, or a clock shifted onto the line
    kNewClock,       ///< a stamp far ahead of its source's clock: placed on a clock of its own
    kSecondClock,    ///< the source interleaves two clocks: the other one is placed on its own
    kHeld            ///< a stamp before its source's clock: not placed, held (see above)
  };
  struct Placed {
    double time = 0.0;  ///< s on the line (not meaningful for kHeld)
    Event event = Event::kNone;
    std::int64_t clock_offset = 0;  ///< ns: the offset of the clock the stamp was placed on
    /// The source's held stamp (held_stamp) was dropped: this stamp continues its clock before.
    bool dropped_held = false;
    /// With kJumpedBack: the held states belong to the new line, before this stamp.
    bool release_held = false;
    ros::Time held_stamp;
  };

  /// Places `stamp`, from `source`, on the line. `clock`: the node's clock (zero: unknown);
  /// `now`: the monitor's time (s on the line, meaningful once started). A kJumpedBack asks
  /// the caller to reset the monitor; a kHeld to keep the input until the source's next one.
  Placed place(const std::string& source, const ros::Time& stamp, const ros::Time& clock,
               double now);

  /// The stamp of an instant of the line in the clock whose offset is `clock_offset` (ns, as
  /// Placed::clock_offset; zero: the node's clock); false when the instant is not a valid
  /// ros::Time (not finite, before 0 or past 2^32 s).
  bool stampOf(double time, std::int64_t clock_offset, ros::Time& stamp) const;
  bool stampOf(double time, ros::Time& stamp) const { return stampOf(time, 0, stamp); }
  /// The instant of the line a stamp of the node's clock is at; false before the line started.
  bool lineTimeOf(const ros::Time& stamp, double& time) const;

  bool started() const { return started_; }
  /// s the source's stamps are shifted by, on its clock heard last (0: none, or unknown).
  double offset(const std::string& source) const;
  /// The source whose stamps started the line.
  const std::string& firstSource() const { return first_source_; }
  /// The sources seen since the line started and the offset of the clock heard last (s).
  std::map<std::string, double> offsets() const;

  struct SourceClocks {
    std::vector<double> offsets;  ///< s, each of its clocks, the one heard last first
    std::uint64_t dropped = 0;    ///< held stamps dropped: off its clock
  };
  /// The sources seen since the line started, their clocks and their dropped stamps.
  std::map<std::string, SourceClocks> sources() const;

  /// Forgets every source and the epoch.
  void reset();

  /// At most this many sources are remembered; the one heard from least recently is forgotten
  /// (a source comes back as a new one): a bound whatever publishers come and go.
  static constexpr std::size_t kMaxSources = 64;
  /// Clocks of one source, at most: the one heard from least recently is forgotten.
  static constexpr std::size_t kMaxClocks = 2;
  /// A stamp of the node's clock may be ahead of the running node's clock by ~clock_jump_back
  /// divided by this (0.1 s by default): well above the difference of clocks that agree (a
  /// /clock heard one 100 Hz tick late, another machine's clock kept by NTP), and a bound on
  /// how far a source whose clock runs fast can carry the line past the present before it is
  /// on a clock of its own.
  static constexpr std::int64_t kAheadFraction = 10;

 private:
  struct Clock {
    std::int64_t offset = 0;      ///< ns added to its stamps
    std::int64_t last_stamp = 0;  ///< ns, its newest stamp
    std::uint64_t heard = 0;      ///< when it was last heard (a counter)
    std::uint64_t messages = 0;
    std::int64_t last_line = 0;   ///< ns, where its last stamp was placed
    std::int64_t last_clock = 0;  ///< ns, the node's clock then (0: unknown)
  };
  struct Held {
    bool active = false;
    bool interrupted = false;  ///< the source's other clock was heard since
    std::int64_t first = 0;    ///< ns, the held stamp
    std::int64_t last = 0;     ///< ns, the newest stamp continuing it
    std::int64_t clock = 0;    ///< ns, the node's clock at `last` (0: unknown)
  };
  struct Source {
    std::vector<Clock> clocks;
    Held held;
    std::uint64_t heard = 0;
    std::uint64_t dropped = 0;
  };

  Placed start(const std::string& source, std::int64_t first, std::int64_t at, std::int64_t clock,
               Event event);
  /// The line's present: the node's clock on the line, when it ran since the last placement
  /// (`clock_runs`); else the line's last instant.
  struct Present {
    std::int64_t line = 0;  ///< ns on the line
    bool clock_runs = false;
    /// Another source that keeps the node's clock (on it, and not ahead of it when last
    /// placed) was heard within ~clock_jump_back of it: the line is shared, and no clock may carry
    /// it past the present (it would put that source's next states in the monitor's past). A source
    /// alone on it keeps its stamps as they are, however they run against the node's clock (a
    /// test's or a simulator's burst of states stamped ahead): there is no one its lead could move.
    bool shared = false;
    std::int64_t node_clock = 0;  ///< ns (0: unknown)
  };
  /// Whether a stamp `at` agrees with the node's clock `clock`: no more than ~clock_jump_back
  /// behind it, nor more than ahead_ns_ ahead of a running one (~clock_jump_back of one that
  /// stood still since the last placement, or at the line's start).
  bool agrees(std::int64_t at, std::int64_t clock, bool clock_runs) const;
  /// The offset of a new clock whose stamp is `at`: zero when it agrees with the node's clock,
  /// else the one that places it at the present.
  std::int64_t newOffset(std::int64_t at, std::int64_t clock, const Present& present) const;
  /// Whether a source other than `source` that keeps the node's clock was heard within
  /// ~clock_jump_back of `node_clock`.
  bool sharedWith(const std::string& source, std::int64_t node_clock) const;
  Placed on(Clock& clock, std::int64_t at, std::int64_t node_clock, std::int64_t now,
            const Present& present);
  bool continues(const Clock& clock, std::int64_t at, const Present& present) const;
  bool continues(const Held& held, std::int64_t at, std::int64_t node_clock) const;
  Source& sourceOf(const std::string& source, bool& is_new);
  /// Adds a clock to the source, forgetting its least recently heard one past kMaxClocks.
  static Clock& addClock(Source& known, const Clock& added);
  /// The source's clock that the stamp `at` continues (the one heard last first), if any.
  Clock* continuedClock(Source& known, std::int64_t at, const Present& present) const;
  /// The source's next stamp after a held one continues the held stamp: a real jump back (every
  /// track reset), or, after an interruption, the source's second clock.
  Placed continueHeld(const std::string& source, Source& known, std::int64_t at,
                      std::int64_t node_clock, std::int64_t now_ns, const Present& present);

  std::int64_t jump_ns_;
  /// ns: how far a stamp of the node's clock may be ahead of it, a tenth of ~clock_jump_back.
  std::int64_t ahead_ns_;
  bool started_ = false;
  std::int64_t epoch_ = 0;       ///< ns: line zero, in the node's clock (offset-zero stamps)
  std::int64_t last_clock_ = 0;  ///< ns: the node's clock at the last placement (0: unknown)
  std::string first_source_;
  std::map<std::string, Source> sources_;
  std::uint64_t heard_ = 0;
};

}  // namespace collision_response
