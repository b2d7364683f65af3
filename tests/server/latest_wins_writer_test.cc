#include "server/latest_wins_writer.h"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <utility>

namespace neuralmesh::server {
namespace {

MeshUpdatePtr Update(uint64_t sequence) {
  auto update = std::make_shared<v1::MeshUpdate>();
  update->set_sequence(sequence);
  return update;
}

// What a reactor does after each event (the step in latest_wins_writer.h): the sequence of
// the update whose write starts, or 0 when none starts.
uint64_t Step(LatestWinsWriter& writer) {
  if (writer.CanWrite() && writer.has_update()) return writer.StartUpdate().sequence();
  return 0;
}

TEST(LatestWinsWriterTest, WritesAtOnceWhenNoWriteIsInFlight) {
  LatestWinsWriter writer;
  EXPECT_TRUE(writer.CanWrite());
  EXPECT_FALSE(writer.has_update());
  writer.Offer(Update(1));
  EXPECT_EQ(Step(writer), 1u);
  EXPECT_FALSE(writer.CanWrite()) << "gRPC allows one outstanding write per stream";
  writer.WriteDone();
  EXPECT_TRUE(writer.CanWrite());
  EXPECT_EQ(Step(writer), 0u) << "nothing waits";
}

TEST(LatestWinsWriterTest, ASlowReaderSkipsToTheNewestUpdate) {
  LatestWinsWriter writer;
  writer.Offer(Update(1));
  ASSERT_EQ(Step(writer), 1u);
  for (uint64_t s = 2; s <= 5; ++s) {
    writer.Offer(Update(s));
    EXPECT_EQ(Step(writer), 0u) << "update " << s << " must wait for the write in flight";
  }
  writer.WriteDone();
  EXPECT_EQ(Step(writer), 5u) << "updates 2-4 are replaced by the newest one";
  writer.WriteDone();
  EXPECT_EQ(Step(writer), 0u) << "at most one update waits: nothing is left";
}

TEST(LatestWinsWriterTest, NeverWritesAnUpdateTwiceOrOlderThanOneOfferedBefore) {
  LatestWinsWriter writer(/*after_sequence=*/5);
  writer.Offer(Update(5));
  writer.Offer(Update(3));
  EXPECT_FALSE(writer.has_update()) << "a resumed watch skips what it saw before";
  writer.Offer(Update(7));
  writer.Offer(Update(6));
  EXPECT_EQ(Step(writer), 7u) << "an older update must not replace a newer one";
  writer.WriteDone();
  writer.Offer(Update(7));
  EXPECT_EQ(Step(writer), 0u) << "update 7 was written already";
}

TEST(LatestWinsWriterTest, KeepsTheUpdateInFlightAliveUntilItsWriteIsDone) {
  LatestWinsWriter writer;
  std::weak_ptr<const v1::MeshUpdate> watched;
  {
    MeshUpdatePtr update = Update(1);
    watched = update;
    writer.Offer(std::move(update));
  }
  ASSERT_EQ(Step(writer), 1u);
  EXPECT_FALSE(watched.expired()) << "gRPC still reads the message";
  writer.WriteDone();
  EXPECT_TRUE(watched.expired()) << "the writer holds no update it has written";
}

TEST(LatestWinsWriterTest, EndWaitsForTheWriteInFlightAndTheWaitingUpdate) {
  LatestWinsWriter writer;
  writer.Offer(Update(1));
  ASSERT_EQ(Step(writer), 1u);
  writer.Offer(Update(2));  // The final mesh, say.
  writer.End(absl::OkStatus());
  EXPECT_TRUE(writer.has_end());
  EXPECT_EQ(writer.TakeFinish(), std::nullopt) << "a write is in flight";
  writer.WriteDone();
  EXPECT_EQ(Step(writer), 2u) << "the waiting update goes out before the end";
  EXPECT_EQ(writer.TakeFinish(), std::nullopt) << "a write is in flight";
  writer.WriteDone();
  EXPECT_EQ(Step(writer), 0u);
  std::optional<absl::Status> end = writer.TakeFinish();
  ASSERT_TRUE(end.has_value()) << "the call finishes once everything is written";
  EXPECT_TRUE(end->ok()) << *end;
  EXPECT_EQ(writer.TakeFinish(), std::nullopt) << "a call finishes exactly once";
  EXPECT_FALSE(writer.CanWrite()) << "nothing is written after Finish";
}

TEST(LatestWinsWriterTest, EndNowDropsTheWaitingUpdateAndWritesNothingMore) {
  LatestWinsWriter writer;
  writer.Offer(Update(1));
  ASSERT_EQ(Step(writer), 1u);
  writer.Offer(Update(2));
  writer.EndNow(absl::CancelledError("the client went away"));
  EXPECT_FALSE(writer.has_update());
  writer.Offer(Update(3));
  EXPECT_FALSE(writer.has_update()) << "nothing is kept after EndNow";
  EXPECT_EQ(writer.TakeFinish(), std::nullopt) << "Finish waits for the write in flight";
  writer.WriteDone();
  EXPECT_FALSE(writer.CanWrite());
  std::optional<absl::Status> end = writer.TakeFinish();
  ASSERT_TRUE(end.has_value());
  EXPECT_TRUE(absl::IsCancelled(*end)) << *end;
}

TEST(LatestWinsWriterTest, TheFirstEndWinsButAbortReplacesIt) {
  LatestWinsWriter ended_ok;
  ended_ok.End(absl::OkStatus());
  ended_ok.EndNow(absl::CancelledError("late"));
  ended_ok.End(absl::NotFoundError("later"));
  std::optional<absl::Status> end = ended_ok.TakeFinish();
  ASSERT_TRUE(end.has_value());
  EXPECT_TRUE(end->ok()) << "the first end wins: " << *end;

  LatestWinsWriter aborted;
  aborted.Offer(Update(1));
  aborted.End(absl::CancelledError("the session was cancelled"));
  aborted.Abort(absl::UnavailableError("the server is shutting down"));
  EXPECT_FALSE(aborted.has_update()) << "Abort drops the waiting update";
  end = aborted.TakeFinish();
  ASSERT_TRUE(end.has_value());
  EXPECT_TRUE(absl::IsUnavailable(*end)) << "Abort replaces an earlier end: " << *end;
}

TEST(LatestWinsWriterTest, OtherMessagesShareTheOneOutstandingWrite) {
  LatestWinsWriter writer;
  writer.StartOther();  // Say, Reconstruct's session.
  writer.Offer(Update(1));
  EXPECT_EQ(Step(writer), 0u) << "the update waits for the other message's write";
  writer.End(absl::OkStatus());
  EXPECT_EQ(writer.TakeFinish(), std::nullopt);
  writer.WriteDone();
  EXPECT_EQ(Step(writer), 1u);
  writer.WriteDone();
  EXPECT_TRUE(writer.TakeFinish().has_value());
}

// Reconstruct's acknowledgements alternate with updates, but the final mesh is the last
// response: a slow reader once got an acknowledgement after it.
TEST(LatestWinsWriterTest, AnAcknowledgementNeverFollowsTheFinalMesh) {
  LatestWinsWriter writer;
  EXPECT_TRUE(AcknowledgementGoesNext(writer, false)) << "no update waits";
  writer.Offer(Update(1));
  EXPECT_FALSE(AcknowledgementGoesNext(writer, false)) << "after an acknowledgement, the update";
  EXPECT_TRUE(AcknowledgementGoesNext(writer, true)) << "after an update, the acknowledgement";

  auto final_update = std::make_shared<v1::MeshUpdate>();
  final_update->set_sequence(2);
  final_update->set_kind(v1::UPDATE_KIND_FINAL);
  writer.Offer(std::move(final_update));
  EXPECT_TRUE(writer.has_final_update());
  EXPECT_TRUE(AcknowledgementGoesNext(writer, false))
      << "an acknowledgement waiting with the final mesh goes before it, whatever went last";
  EXPECT_FALSE(writer.final_written());
  ASSERT_EQ(Step(writer), 2u);
  EXPECT_TRUE(writer.final_written()) << "nothing may be written after this";
  EXPECT_FALSE(writer.has_final_update());
}

}  // namespace
}  // namespace neuralmesh::server
