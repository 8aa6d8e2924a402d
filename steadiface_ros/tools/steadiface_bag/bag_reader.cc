#include "steadiface_bag/bag_reader.h"

#include <iostream>
#include <map>

#include <type_traits>

#include <ros/serialization.h>
#include <rosbag/view.h>
#include <sensor_msgs/CompressedImage.h>

#include "steadiface_ros/msg_conversion.h"

namespace steadiface_bag {

std::string NormalizeTopic(const std::string& t) {
  return t.empty() || t[0] == '/' ? t : "/" + t;
}

BagReader::~BagReader() { Join(); }

steadiface::Status BagReader::Open(bool info_required) {
  using steadiface::Status;
  std::map<std::string, std::string> types;  // topic -> type
  // The indexed reader first: a rosbag::Bag is not even constructed when it
  // reads the bag (constructing one loads rosbag's encryptor plugins, about
  // 40 ms of every start).
  std::string why_not_indexed;
  if (use_indexed_reader_) {
    fast_.reset(new IndexedBagReader(verify_checksums_));
    if (fast_->Open(path_, &why_not_indexed)) {
      for (const auto& c : fast_->connections()) {
        types[NormalizeTopic(c.second.topic)] = c.second.datatype;
      }
    } else {
      fast_.reset();  // rosbag reads what it refuses, or says what is wrong
    }
  }
  if (!fast_) {
    bag_.reset(new rosbag::Bag);
    try {
      bag_->open(path_, rosbag::bagmode::Read);
    } catch (const rosbag::BagException& e) {
      return Status::Error("cannot open '" + path_ + "': " + e.what());
    }
    if (!why_not_indexed.empty()) {
      std::cerr << "steadiface_bag: reading " << path_
                << " through rosbag::View (" << why_not_indexed << ")\n";
    }
    rosbag::View all(*bag_);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      types[NormalizeTopic(c->topic)] = c->datatype;
    }
  }
  const std::vector<std::pair<std::string, std::string>> want = {
      {topics_.image, "sensor_msgs/Image"},
      {topics_.info, "sensor_msgs/CameraInfo"},
      {topics_.imu, "sensor_msgs/Imu"}};
  for (const auto& w : want) {
    auto it = types.find(NormalizeTopic(w.first));
    if (it == types.end()) {
      const bool is_info = w.second == "sensor_msgs/CameraInfo";
      if (is_info && !info_required)
        continue;  // intrinsics from camera_info_url
      std::cerr << "steadiface_bag: topic '" << NormalizeTopic(w.first) << "' ("
                << w.second << ") is not in " << path_ << "; topics there:";
      for (const auto& t : types)
        std::cerr << " " << t.first << " [" << t.second << "]";
      std::cerr << "\n";
      if (is_info) {
        return Status::Error(
            "no camera_info: name its topic with --info, or give the "
            "intrinsics with a "
            "camera_info_url in a --params file");
      }
      if (w.second != "sensor_msgs/Imu") return Status::Error("no image topic");
      std::cerr << "steadiface_bag: continuing without IMU: the rotation comes "
                   "from the video (rotation_source auto or visual), or frames "
                   "pass through unstabilized (imu)\n";
    } else if (w.second == "sensor_msgs/Image" &&
               it->second == "sensor_msgs/CompressedImage") {
      compressed_ = true;
    } else if (it->second != w.second) {
      return Status::Error("topic '" + NormalizeTopic(w.first) + "' has type " +
                           it->second + ", expected " + w.second);
    } else if (w.second == "sensor_msgs/CameraInfo") {
      has_info_ = true;
    }
  }
  return Status::Ok();
}

std::vector<std::string> BagReader::WithAndWithoutSlash(
    const std::string& t) const {
  std::vector<std::string> v = {NormalizeTopic(t)};
  if (NormalizeTopic(t).size() > 1) v.push_back(NormalizeTopic(t).substr(1));
  return v;
}

size_t BagReader::Count(const std::string& topic) const {
  if (fast_) return fast_->Count(WithAndWithoutSlash(topic));
  if (!bag_) return 0;
  return rosbag::View(*bag_, rosbag::TopicQuery(WithAndWithoutSlash(topic))).size();
}

size_t BagReader::ImageCount() const { return Count(topics_.image); }

size_t BagReader::ImuCount() const { return Count(topics_.imu); }

template <typename As>
bool BagReader::Dispatch(const std::string& raw_topic, const ros::Time& time, As as,
                         BoundedQueue<BagItem>* queue) {
  BagItem item;
  const std::string topic = NormalizeTopic(raw_topic);
  item.time = time;
  if (topic == imu_) {
    item.imu = as(static_cast<sensor_msgs::Imu*>(nullptr));
  } else if (topic == info_) {
    item.info = as(static_cast<sensor_msgs::CameraInfo*>(nullptr));
  } else if (topic == landmarks_) {
    item.landmarks = as(static_cast<steadiface::FaceLandmarks*>(nullptr));
  } else if (topic == image_ && !compressed_) {
    item.image = as(static_cast<sensor_msgs::Image*>(nullptr));
  } else if (topic == image_) {
    sensor_msgs::CompressedImageConstPtr c =
        as(static_cast<sensor_msgs::CompressedImage*>(nullptr));
    sensor_msgs::ImagePtr decoded;
    const steadiface::Status s =
        c ? steadiface_ros::FromCompressedImage(*c, &decoded)
          : steadiface::Status::Error("not a sensor_msgs/CompressedImage");
    if (s.ok()) {
      item.image = decoded;
    } else if (decode_failures_++ == 0) {
      std::cerr << "steadiface_bag: " << s.message() << " (frame skipped)\n";
    }
  }
  return queue->Push(std::move(item));
}

void BagReader::ReadIndexed(const std::vector<std::string>& topics,
                            BoundedQueue<BagItem>* queue) {
  fast_->Select(topics);
  IndexedBagReader::Message m;
  std::string err;
  while (fast_->Next(&m, &err)) {
    const std::string& topic = fast_->connections().at(m.connection).topic;
    const std::string& datatype = fast_->connections().at(m.connection).datatype;
    auto as = [this, &m, &topic, &datatype](auto* type) {
      using M = std::remove_pointer_t<decltype(type)>;
      // As MessageInstance::instantiate: null for another type.
      if (datatype != ros::message_traits::datatype<M>()) {
        return boost::shared_ptr<const M>();
      }
      boost::shared_ptr<M> msg(new M);
      try {
        ros::serialization::IStream s(const_cast<uint8_t*>(m.data), m.size);
        ros::serialization::deserialize(s, *msg);
      } catch (const ros::Exception& e) {
        // A damaged message (rosbag::View would stop the whole read).
        if (decode_failures_++ == 0) {
          std::cerr << "steadiface_bag: a message on " << topic
                    << " does not deserialize (" << e.what() << "; skipped)\n";
        }
        msg.reset();
      }
      return boost::shared_ptr<const M>(msg);
    };
    if (!Dispatch(topic, m.time, as, queue)) break;
  }
  if (!err.empty()) error_ = err;
}

void BagReader::ReadView(const std::vector<std::string>& topics, BoundedQueue<BagItem>* queue) {
  rosbag::View view(*bag_, rosbag::TopicQuery(topics));
  for (const rosbag::MessageInstance& m : view) {
    auto as = [&m](auto* type) {
      using M = std::remove_pointer_t<decltype(type)>;
      return boost::shared_ptr<const M>(m.instantiate<M>());
    };
    if (!Dispatch(m.getTopic(), m.getTime(), as, queue)) break;
  }
}

void BagReader::ReadAll(BoundedQueue<BagItem>* queue) {
  std::vector<std::string> topics;
  for (const std::string& t : {topics_.image, topics_.info, topics_.imu, topics_.landmarks}) {
    if (t.empty()) continue;
    for (const auto& v : WithAndWithoutSlash(t)) topics.push_back(v);
  }
  imu_ = NormalizeTopic(topics_.imu);
  info_ = NormalizeTopic(topics_.info);
  landmarks_ = NormalizeTopic(topics_.landmarks);
  image_ = NormalizeTopic(topics_.image);
  try {
    if (fast_) {
      ReadIndexed(topics, queue);
    } else if (bag_) {
      ReadView(topics, queue);
    }
  } catch (const std::exception& e) {
    error_ = e.what();
  }
  queue->Close();
}

void BagReader::Start(BoundedQueue<BagItem>* queue) {
  thread_ = std::thread([this, queue] { ReadAll(queue); });
}

std::string BagReader::Join() {
  if (thread_.joinable()) thread_.join();
  return error_;
}

}  // namespace steadiface_bag
