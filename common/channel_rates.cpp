#include "common/channel_rates.hpp"

namespace sg {

ChannelRates::Row& ChannelRates::row(const std::string& channel) {
  for (Row& r : rows_)
    if (r.channel == channel) return r;
  if (rows_.size() + 1 >= kMaxChannels) {  // the last row is "(other)"
    if (rows_.size() + 1 == kMaxChannels) rows_.push_back({kOther});
    return rows_.back();
  }
  return rows_.emplace_back(Row{channel});
}

void ChannelRates::fill(stereograsp::process_status_t& status, double now) {
  const double interval = last_fill_ < 0 ? 0 : now - last_fill_;
  last_fill_ = now;
  status.channel.clear();
  status.messages_in.clear();
  status.messages_out.clear();
  status.rate_in_hz.clear();
  status.rate_out_hz.clear();
  for (Row& r : rows_) {
    status.channel.push_back(r.channel);
    status.messages_in.push_back(r.in);
    status.messages_out.push_back(r.out);
    status.rate_in_hz.push_back(interval > 0 ? (r.in - r.in_before) / interval : 0.0);
    status.rate_out_hz.push_back(interval > 0 ? (r.out - r.out_before) / interval : 0.0);
    r.in_before = r.in;
    r.out_before = r.out;
  }
  status.num_channels = static_cast<int32_t>(status.channel.size());
}

}  // namespace sg
