#include "server/update_channel.h"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <vector>

namespace neuralmesh::server {
namespace {

class RecordingSubscriber : public UpdateSubscriber {
 public:
  void OnUpdate(const MeshUpdatePtr& update) override { sequences.push_back(update->sequence()); }
  void OnClose(const absl::Status& status) override { closed = status; }
  std::vector<uint64_t> sequences;
  std::optional<absl::Status> closed;
};

std::shared_ptr<v1::MeshUpdate> Update(uint64_t vertices) {
  auto update = std::make_shared<v1::MeshUpdate>();
  update->set_vertex_count(vertices);
  return update;
}

TEST(UpdateChannelTest, NumbersUpdatesAndKeepsOnlyTheLatest) {
  UpdateChannel channel;
  EXPECT_EQ(channel.latest(), nullptr);
  EXPECT_EQ(channel.Publish(Update(10)), 1u);
  EXPECT_EQ(channel.Publish(Update(20)), 2u);
  ASSERT_NE(channel.latest(), nullptr);
  EXPECT_EQ(channel.latest()->sequence(), 2u);
  EXPECT_EQ(channel.latest()->vertex_count(), 20u) << "the channel holds the newest update only";
}

TEST(UpdateChannelTest, ANewSubscriberGetsTheLatestAtOnce) {
  UpdateChannel channel;
  channel.Publish(Update(10));
  channel.Publish(Update(20));
  RecordingSubscriber late;
  const uint64_t handle = channel.Subscribe(&late, 0);
  EXPECT_EQ(late.sequences, std::vector<uint64_t>({2})) << "a late watcher starts from the latest";
  channel.Publish(Update(50));
  EXPECT_EQ(late.sequences, std::vector<uint64_t>({2, 3}));
  channel.Unsubscribe(handle);
  channel.Publish(Update(100));
  EXPECT_EQ(late.sequences.size(), 2u) << "no call after Unsubscribe";
}

TEST(UpdateChannelTest, ResumingSubscriberSkipsWhatItHasSeen) {
  UpdateChannel channel;
  channel.Publish(Update(10));
  RecordingSubscriber resumed;
  channel.Subscribe(&resumed, 1);
  EXPECT_TRUE(resumed.sequences.empty()) << "after_sequence 1 already covers update 1";
}

TEST(UpdateChannelTest, ARestoredUpdateIsTheLatestAndItsNumbersGoOn) {
  UpdateChannel channel;
  auto stored = Update(300);
  stored->set_sequence(7);
  channel.Restore(stored);
  EXPECT_EQ(channel.latest()->vertex_count(), 300u);
  EXPECT_EQ(channel.next_sequence(), 8u);
  RecordingSubscriber resumed;
  channel.Subscribe(&resumed, 7);
  EXPECT_TRUE(resumed.sequences.empty()) << "a watcher that had update 7 is not sent it again";
  EXPECT_EQ(channel.Publish(Update(400)), 8u);
  EXPECT_EQ(resumed.sequences, std::vector<uint64_t>({8}));
}

TEST(UpdateChannelTest, CloseIsFinalAndReplayedToLateSubscribers) {
  UpdateChannel channel;
  RecordingSubscriber early;
  channel.Subscribe(&early, 0);
  channel.Publish(Update(10));
  channel.Close(absl::OkStatus());
  EXPECT_EQ(channel.Publish(Update(20)), 0u) << "publishing after close is dropped";
  ASSERT_TRUE(early.closed.has_value());
  EXPECT_TRUE(early.closed->ok());
  channel.Close(absl::CancelledError("later"));
  EXPECT_TRUE(channel.close_status()->ok()) << "the first close wins";

  RecordingSubscriber late;
  channel.Subscribe(&late, 0);
  EXPECT_EQ(late.sequences, std::vector<uint64_t>({1})) << "the final mesh, then the close";
  ASSERT_TRUE(late.closed.has_value());
  EXPECT_TRUE(late.closed->ok());
}

}  // namespace
}  // namespace neuralmesh::server
