#include "server/latest_wins_writer.h"

#include <utility>

namespace neuralmesh::server {

LatestWinsWriter::LatestWinsWriter(uint64_t after_sequence) : last_sequence_(after_sequence) {}

void LatestWinsWriter::Offer(MeshUpdatePtr update) {
  // The channel delivers in sequence order; the check also keeps a resumed watch from seeing
  // what it saw before, and a stopped stream from growing after its end.
  if (stopped_ || finished_ || update->sequence() <= last_sequence_) return;
  last_sequence_ = update->sequence();
  pending_ = std::move(update);
}

void LatestWinsWriter::End(const absl::Status& status) {
  if (!end_.has_value()) end_ = status;
}

void LatestWinsWriter::EndNow(const absl::Status& status) {
  End(status);
  stopped_ = true;
  pending_.reset();
}

void LatestWinsWriter::Abort(const absl::Status& status) {
  end_ = status;
  stopped_ = true;
  pending_.reset();
}

const v1::MeshUpdate& LatestWinsWriter::StartUpdate() {
  in_flight_ = std::move(pending_);
  pending_.reset();
  writing_ = true;
  final_written_ |= in_flight_->kind() == v1::UPDATE_KIND_FINAL;
  return *in_flight_;
}

void LatestWinsWriter::StartOther() { writing_ = true; }

void LatestWinsWriter::WriteDone() {
  writing_ = false;
  in_flight_.reset();
}

std::optional<absl::Status> LatestWinsWriter::TakeFinish() {
  if (finished_ || writing_ || !end_.has_value()) return std::nullopt;
  // A waiting update goes out before the end unless writing stopped: that is how the final
  // mesh always precedes OK.
  if (!stopped_ && pending_ != nullptr) return std::nullopt;
  finished_ = true;
  return end_;
}

bool AcknowledgementGoesNext(const LatestWinsWriter& writer, bool last_write_was_update) {
  return !writer.has_update() || last_write_was_update || writer.has_final_update();
}

}  // namespace neuralmesh::server
