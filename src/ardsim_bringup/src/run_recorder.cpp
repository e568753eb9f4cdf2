// run_recorder: records topics into a bag as `rosbag record TOPICS` does (the same bag: message definitions,
// connection headers with their latching, receipt times on the sim clock), with subscriber queues deep enough
// that a burst loses nothing.
//
// Why not rosbag record: its subscriber queues hold 100 messages (hard-coded). The recorder sits outside the
// lockstep and takes ~190 MB/s of clouds in the default run; it falls behind, the publishers keep its
// messages (their queues hold 1000), and when it catches up a topic's backlog arrives at once and all but the
// newest 100 are discarded: the default run's bag lacked 13 consecutive /pose/error, /guidance/command and
// /truth/chaser/odom messages at 208 s ("Incoming queue was full for topic /pose/error" in its debug log).
//
// It also keeps up with the lockstep rather than lose messages: it publishes record/progress
// (rosgraph_msgs/Clock, latched), the latest stamp up to which every progress topic has been written, and
// the dynamics (~recorder_lag_steps) does not run more than so many steps ahead of it. A publisher's queue to
// the recorder then never overflows, however slow the disk or loaded the machine. (Outside the lockstep, this
// recorder fell 2500 steps behind on the dynamics' topics while two default runs shared 2 cores, and the
// lidar's queue of 500 frames discarded clouds.)
//
// Private parameters:
//   bag: string, required. The bag to write; BAG.active while recording, renamed to BAG when closed.
//   topics: string, required. Topics to record, space-separated, subscribed in this order.
//   progress_topics: string, default "". Topics among `topics` published once a step with a std_msgs/Header
//     stamped with the step's time; record/progress is the oldest of their latest stamps.
//   buffer_mb: int, 0 .. 65536, default 256 (0 = unlimited). Messages held for the writer, in MB; beyond it
//     the oldest are dropped (as rosbag record's --buffsize), each drop counted and logged.
// Ends on SIGINT (roslaunch's stop): writes what it holds, closes the bag, logs what it recorded and dropped.
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosgraph_msgs/Clock.h>
#include <topic_tools/shape_shifter.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace {

// Set by SIGINT / SIGTERM: the node stays up until the bag is closed and its summary logged.
std::atomic<bool> g_stop{false};
void requestStop(int) {
  g_stop = true;
}

// Deeper than any backlog a publisher can hand over at once (the graph's publishers queue 1000): a burst is
// taken whole, and the byte budget (buffer_mb) is the only limit.
constexpr std::uint32_t kSubscriberQueue = 10000;

struct Received {
  std::string topic;
  ros::Time receipt_time;
  topic_tools::ShapeShifter::ConstPtr message;
  boost::shared_ptr<ros::M_string> connection_header;
};

// Whether a message type's first field is a std_msgs/Header, from its definition.
bool startsWithHeader(const std::string& definition_text) {
  std::istringstream definition(definition_text);
  for (std::string line; std::getline(definition, line);) {
    const std::size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line[start] == '#') continue;
    std::istringstream field(line.substr(start));
    std::string type;
    field >> type;
    return type == "Header" || type == "std_msgs/Header";
  }
  return false;
}

// The header stamp (after its seq) of a message that starts with a std_msgs/Header, from its serialized
// bytes.
bool headerStamp(const topic_tools::ShapeShifter& message, ros::Time* stamp) {
  if (message.size() < 12) return false;
  // ShapeShifter hands out its bytes only by copying them into a stream.
  struct Bytes {
    std::vector<std::uint8_t> data;
    std::uint8_t* advance(std::uint32_t n) {
      data.resize(n);
      return data.data();
    }
  } bytes;
  message.write(bytes);
  std::uint32_t sec = 0, nsec = 0;
  std::memcpy(&sec, bytes.data.data() + 4, 4);
  std::memcpy(&nsec, bytes.data.data() + 8, 4);
  *stamp = ros::Time(sec, nsec);
  return true;
}

struct ProgressTopic {
  ros::Time latest;      // the latest stamp written
  int with_header = -1;  // its type starts with a std_msgs/Header: 1 / 0, -1 before its first message
};

class RunRecorder {
 public:
  RunRecorder(const std::string& bag_path, std::size_t buffer_bytes,
              const std::vector<std::string>& progress_topics, ros::NodeHandle& nh)
      : bag_path_(bag_path), buffer_bytes_(buffer_bytes) {
    for (const std::string& topic : progress_topics) progress_topics_[topic] = ProgressTopic{};
    if (!progress_topics_.empty())
      progress_publisher_ = nh.advertise<rosgraph_msgs::Clock>("record/progress", 10, true);
    bag_.open(bag_path_ + ".active", rosbag::bagmode::Write);
  }

  void subscribe(ros::NodeHandle& nh, const std::string& topic) {
    ros::SubscribeOptions options;
    options.topic = topic;
    options.queue_size = kSubscriberQueue;
    options.md5sum = ros::message_traits::md5sum<topic_tools::ShapeShifter>();
    options.datatype = ros::message_traits::datatype<topic_tools::ShapeShifter>();
    options.helper = boost::make_shared<
        ros::SubscriptionCallbackHelperT<const ros::MessageEvent<topic_tools::ShapeShifter const>&>>(
        [this, topic](const ros::MessageEvent<topic_tools::ShapeShifter const>& event) {
          receive(event, topic);
        });
    subscribers_[topic] = nh.subscribe(options);
    recorded_[topic] = 0;
  }

  // Writes until SIGINT (or the node's shutdown), then what is still held; closes the bag.
  void writeUntilStopped() {
    for (;;) {
      std::unique_lock<std::mutex> lock(mutex_);
      received_.wait_for(lock, std::chrono::milliseconds(250), [this] { return !held_.empty(); });
      if (held_.empty()) {
        if (g_stop || !ros::ok()) break;
        continue;
      }
      const Received next = std::move(held_.front());
      held_.pop_front();
      held_bytes_ -= next.message->size();
      lock.unlock();
      bag_.write(next.topic, next.receipt_time, *next.message, next.connection_header);
      ++recorded_[next.topic];
      const auto progress_topic = progress_topics_.find(next.topic);
      if (progress_topic != progress_topics_.end()) markWritten(&progress_topic->second, *next.message);
    }
    subscribers_.clear();
    bag_.close();
    if (std::rename((bag_path_ + ".active").c_str(), bag_path_.c_str()) != 0)
      ROS_ERROR("run_recorder: could not rename %s.active to %s", bag_path_.c_str(), bag_path_.c_str());
    std::ostringstream summary;
    for (const auto& [topic, count] : recorded_) summary << " " << topic << " " << count;
    ROS_INFO("run_recorder: closed %s; messages recorded:%s", bag_path_.c_str(), summary.str().c_str());
    if (dropped_ > 0)
      ROS_ERROR("run_recorder: dropped %zu messages beyond buffer_mb (the disk fell behind)", dropped_);
  }

 private:
  void receive(const ros::MessageEvent<topic_tools::ShapeShifter const>& event, const std::string& topic) {
    Received r{topic, ros::Time::now(), event.getMessage(), event.getConnectionHeaderPtr()};
    {
      std::lock_guard<std::mutex> lock(mutex_);
      held_bytes_ += r.message->size();
      held_.push_back(std::move(r));
      while (buffer_bytes_ > 0 && held_bytes_ > buffer_bytes_ && held_.size() > 1) {
        held_bytes_ -= held_.front().message->size();
        held_.pop_front();
        ++dropped_;
        ROS_WARN_THROTTLE(5.0, "run_recorder: buffer_mb exceeded, dropping the oldest message (%zu so far)",
                          dropped_);
      }
    }
    received_.notify_one();
  }

  // Progress is counted once written, not received (the lockstep then waits for the disk too, rather than
  // fill buffer_mb and drop), by the writer thread alone.
  void markWritten(ProgressTopic* written, const topic_tools::ShapeShifter& message) {
    if (written->with_header < 0) written->with_header = startsWithHeader(message.getMessageDefinition());
    ros::Time stamp;
    if (written->with_header == 0 || !headerStamp(message, &stamp)) {
      ROS_ERROR_THROTTLE(5.0, "run_recorder: a progress topic's type %s has no header: it cannot mark a step",
                         message.getDataType().c_str());
      return;
    }
    written->latest = std::max(written->latest, stamp);
    // A progress topic with no publisher (its node died; until it is respawned) holds nothing back: the
    // lockstep goes on without it (guidance holds), and so would the dynamics' wait for the recorder, for
    // recorder_timeout_s and then for good.
    ros::Time oldest = written->latest;
    for (const auto& [name, topic] : progress_topics_) {
      const auto subscriber = subscribers_.find(name);
      if (subscriber == subscribers_.end() || subscriber->second.getNumPublishers() > 0)
        oldest = std::min(oldest, topic.latest);
    }
    if (oldest <= progress_) return;
    progress_ = oldest;
    rosgraph_msgs::Clock progress;
    progress.clock = progress_;
    progress_publisher_.publish(progress);
  }

  const std::string bag_path_;
  const std::size_t buffer_bytes_;
  std::map<std::string, ProgressTopic> progress_topics_;
  ros::Time progress_;
  ros::Publisher progress_publisher_;
  rosbag::Bag bag_;
  std::map<std::string, ros::Subscriber> subscribers_;  // by topic
  std::mutex mutex_;
  std::condition_variable received_;
  std::deque<Received> held_;
  std::size_t held_bytes_ = 0;
  std::size_t dropped_ = 0;
  std::map<std::string, std::size_t> recorded_;  // written by the writer only
};

[[noreturn]] void badParameter(const std::string& name, const std::string& value,
                               const std::string& allowed) {
  ROS_FATAL("run_recorder: parameter ~%s = '%s' is invalid (allowed: %s)", name.c_str(), value.c_str(),
            allowed.c_str());
  std::exit(1);
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "run_recorder", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");

  std::string bag_path;
  std::string topics_text;
  std::string progress_text;
  int buffer_mb = 256;
  private_nh.param<std::string>("bag", bag_path, "");
  private_nh.param<std::string>("topics", topics_text, "");
  private_nh.param<std::string>("progress_topics", progress_text, "");
  private_nh.param("buffer_mb", buffer_mb, buffer_mb);
  if (bag_path.empty()) badParameter("bag", bag_path, "a file path");
  std::vector<std::string> topics;
  std::istringstream words(topics_text);
  for (std::string topic; words >> topic;) topics.push_back(topic);
  if (topics.empty()) badParameter("topics", topics_text, "one or more topic names, space-separated");
  std::vector<std::string> progress_topics;
  std::istringstream progress_words(progress_text);
  for (std::string topic; progress_words >> topic;) {
    if (std::find(topics.begin(), topics.end(), topic) == topics.end())
      badParameter("progress_topics", progress_text, "topics among ~topics, space-separated");
    progress_topics.push_back(topic);
  }
  if (buffer_mb < 0 || buffer_mb > 65536) badParameter("buffer_mb", std::to_string(buffer_mb), "0 .. 65536");

  try {
    RunRecorder recorder(bag_path, static_cast<std::size_t>(buffer_mb) << 20, progress_topics, nh);
    for (const std::string& topic : topics) recorder.subscribe(nh, topic);
    ROS_INFO("run_recorder: recording %zu topics to %s", topics.size(), bag_path.c_str());
    // Receipt times are on the sim clock, as rosbag record's: the callbacks wait for the first /clock (a bag
    // refuses time 0; what arrives before waits in the subscriber queues).
    while (!g_stop && ros::ok() && !ros::Time::waitForValid(ros::WallDuration(0.1))) {
    }
    // Several threads: one topic's callbacks run one at a time, so a cloud being queued holds up no other
    // topic.
    ros::AsyncSpinner spinner(4);
    // Stopped before the first /clock (a run that could not start): nothing is taken (a message at time 0,
    // run/outcome, would throw), and the bag is closed empty.
    if (ros::Time::isValid()) spinner.start();
    recorder.writeUntilStopped();
  } catch (const rosbag::BagException& e) {
    ROS_FATAL("run_recorder: %s", e.what());
    return 1;
  }
  ros::shutdown();
  return 0;
}
