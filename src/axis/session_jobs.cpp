// The object job queue (one transfer at a time, FIFO), the start-up reads, the polling of what the
// cyclic data does not carry, and objects read and written with their types.
#include "cia402/words.hpp"
#include "session_internal.hpp"

namespace cia402::axes {
namespace {

bool is_size_refusal(sdo_abort a) noexcept {
  return a == sdo_abort::data_type_length_too_low || a == sdo_abort::data_type_length_mismatch;
}

}  // namespace

void session::queue_upload(std::uint16_t index, std::uint8_t sub, transfer_done done, bool front) {
  auto j = std::make_unique<job>();
  j->index = index;
  j->sub = sub;
  j->done = std::move(done);
  if (front) {
    jobs_.push_front(std::move(j));
  } else {
    jobs_.push_back(std::move(j));
  }
}

void session::queue_download(std::uint16_t index, std::uint8_t sub, std::vector<std::uint8_t> bytes,
                             transfer_done done) {
  auto j = std::make_unique<job>();
  j->index = index;
  j->sub = sub;
  j->download = true;
  j->bytes = std::move(bytes);
  j->done = std::move(done);
  jobs_.push_back(std::move(j));
}

void session::run_jobs() {
  if (link_->phase() == link_phase::failed) {
    // Nothing queued will run on this link as it is: said now, not after a time-out.
    std::deque<std::unique_ptr<job>> gone;
    gone.swap(jobs_);
    transfer_result r;
    r.cancelled = true;
    r.error = link_->phase_text();
    for (auto& j : gone) {
      if (j->done) j->done(r);
    }
    return;
  }
  // The jobs queued now, at most: one the link refuses is answered at once and the next one tried;
  // what their completions queue runs from the next poll.
  for (std::size_t tries = jobs_.size() + 1; tries > 0; --tries) {
    if (transfer_busy_ || link_->phase() != link_phase::running) return;
    if (jobs_.empty()) {
      (void)poll_due();
      return;
    }
    std::unique_ptr<job> j = std::move(jobs_.front());
    jobs_.pop_front();
    transfer_busy_ = true;
    auto done = [this, done = std::move(j->done)](const transfer_result& r) {
      transfer_busy_ = false;
      if (done) done(r);
    };
    const bool no_bytes = j->download && j->bytes.empty();
    const bool queued = j->download ? link_->download(j->index, j->sub, std::move(j->bytes), done)
                                    : link_->upload(j->index, j->sub, done);
    if (queued) return;
    if (link_->phase() != link_phase::running) {
      transfer_busy_ = false;
      jobs_.push_front(std::move(j));  // the link is not running after all: it runs when it is
      return;
    }
    // A running link that refuses the transfer itself (a bus's SDO carries at least one byte) will
    // refuse it each time: it fails now, or it would stand before every later transfer for ever.
    transfer_result r;
    r.error = link_->short_name() + " refused the transfer" + (no_bytes ? ": a download of no bytes" : "");
    done(r);
  }
}

bool session::poll_due() {
  for (auto& [index, p] : polled_) {
    if (p.wanted <= 0 || p.absent || p.next_us > now_us_) continue;
    if (link_->cyclic() && link_->cyclic_input(index, 0)) continue;  // carried: nothing to read
    p.next_us = now_us_ + config_.poll_us;
    const std::uint16_t i = index;
    const object_description* o = find_drive_object(i, 0);
    // The core's table, else what the link knows of its bus's objects (0x1001, the error register).
    const std::optional<value_format> f = o != nullptr ? std::optional(axes::format_of(o->type)) : link_->describe(i, 0);
    transfer_busy_ = true;
    const bool queued = link_->upload(i, 0, [this, i, f](const transfer_result& r) {
      transfer_busy_ = false;
      polled& q = polled_[i];
      if (r.ok) {
        const object_value v = decode_value(r.data, f);
        if (v.what == value_format::kind::integer) {
          q.value = v.number;
          q.read_us = now_us_;
        }
      } else if (r.abort != sdo_abort::none) {
        q.absent = true;  // the drive has no such object (or will not say): not asked again
      }
    });
    if (!queued) transfer_busy_ = false;
    return true;
  }
  return false;
}

void session::start_up_reads() {
  start_up_queued_ = true;
  prepared_ = false;
  options_ = make_axis(*profile_);
  for (int k = 0; k < option_count; ++k) {
    const std::uint16_t index = option_index(static_cast<option>(k));
    queue_upload(index, 0, [this, index](const transfer_result& r) {
      if (!r.ok || r.data.empty() || r.data.size() > 2) return;  // absent: the profile's default
      const object_value v = decode_value(r.data, value_format::integer(static_cast<unsigned>(r.data.size()), true));
      (void)write_option(*profile_, options_, index, static_cast<std::int32_t>(v.number));
    });
  }
  queue_upload(object_index::supported_drive_modes, 0, [this](const transfer_result& r) {
    if (r.ok && r.data.size() == 4) {
      supported_modes_ = static_cast<std::uint32_t>(decode_value(r.data, value_format::integer(4, false)).number);
    } else if (!r.cancelled) {
      supported_modes_.reset();
    }
  });
  queue_upload(object_index::modes_of_operation_display, 0, [this](const transfer_result& r) {
    if (!r.ok || r.data.size() != 1) return;
    polled& p = polled_[object_index::modes_of_operation_display];
    p.value = static_cast<std::int8_t>(r.data[0]);
    p.read_us = now_us_;
  });
  queue_upload(device_name_index, 0, [this](const transfer_result& r) {
    if (r.cancelled) return;  // start-up runs again when the link does
    if (r.ok) device_name_ = decode_value(r.data, value_format::text()).text;
    prepared_ = true;
  });
}

std::optional<value_format> session::format_of(std::uint16_t index, std::uint8_t sub) const {
  if (const object_description* o = find_drive_object(index, sub)) return axes::format_of(o->type);
  return link_->describe(index, sub);
}

// --- objects by request -------------------------------------------------------------------------

std::uint64_t session::read_object(std::uint16_t index, std::uint8_t sub, completion done) {
  const std::uint64_t id = next_id_++;
  const std::optional<value_format> f = format_of(index, sub);
  queue_upload(index, sub, [this, id, index, sub, f, done](const transfer_result& r) {
    result res;
    res.id = id;
    res.format = f;
    if (r.ok) {
      res.value = decode_value(r.data, f);
      // Bytes that do not fit the type known are shown as bytes, with no type claimed for them.
      if (f && res.value->what != f->what) res.format.reset();
    } else {
      res.end = outcome::failed;
      res.abort = r.abort;
      res.error = "reading " + object_name(index, sub) + ": " + transfer_failure(r);
    }
    fill_result(res);
    if (done) done(res);
  });
  return id;
}

std::uint64_t session::write_object(std::uint16_t index, std::uint8_t sub, const object_value& v, completion done) {
  const std::uint64_t id = next_id_++;
  auto res = std::make_shared<result>();
  res->id = id;
  res->value = v;
  res->format = format_of(index, sub);
  const auto refuse = [&](std::string why) {
    res->end = outcome::failed;
    res->bad_input = true;
    res->error = "writing " + object_name(index, sub) + ": " + why;
    // From the next poll, as every completion.
    deferred_.push_back([this, res, done] {
      fill_result(*res);
      if (done) done(*res);
    });
    return id;
  };
  if (const object_description* o = find_drive_object(index, sub)) {
    if (v.what != value_format::kind::integer) return refuse("it is " + res->format->type_name() + ", not " + (v.what == value_format::kind::text ? "a text" : "bytes"));
    if (const sdo_abort a = check_write(*o, v.number); a != sdo_abort::none) {
      res->abort = a;
      return refuse(std::to_string(v.number) + " is refused by the object table: " + sdo_abort_text(a) + " (" +
                    std::to_string(o->low) + ".." + std::to_string(o->high) + ", " + o->name + ")");
    }
    if (link_->cyclic() && put_output(index, sub, v.number)) {
      res->note = "written into the cyclic outputs";
      deferred_.push_back([this, res, done] {
        fill_result(*res);
        if (done) done(*res);
      });
      return id;
    }
  }
  if (!res->format && v.what == value_format::kind::integer) {
    write_object_sized(index, sub, v.number, smallest_size(v.number), res, std::move(done));
    return id;
  }
  std::vector<std::uint8_t> bytes;
  std::string why;
  if (res->format && !encode_value(v, *res->format, bytes, why)) return refuse(why);
  if (!res->format) bytes = v.what == value_format::kind::text ? std::vector<std::uint8_t>(v.text.begin(), v.text.end()) : v.bytes;
  queue_download(index, sub, std::move(bytes), [this, res, index, sub, done](const transfer_result& r) {
    if (!r.ok) {
      res->end = outcome::failed;
      res->abort = r.abort;
      res->error = "writing " + object_name(index, sub) + ": " + transfer_failure(r);
    }
    bool is_option = false;
    for (int k = 0; k < option_count; ++k) is_option |= sub == 0 && index == option_index(static_cast<option>(k));
    if (!is_option || r.cancelled) {
      fill_result(*res);
      if (done) done(*res);
      return;
    }
    // An option code is what the drive reads back, whatever the write's answer said: a lost or
    // garbled answer can make a write the drive took look refused. The planner, the stops and the
    // lease use it.
    queue_upload(index, 0, [this, res, index, done](const transfer_result& back) {
      if (back.ok && !back.data.empty() && back.data.size() <= 2) {
        const object_value read_back =
            decode_value(back.data, value_format::integer(static_cast<unsigned>(back.data.size()), true));
        (void)write_option(*profile_, options_, index, static_cast<std::int32_t>(read_back.number));
      }
      fill_result(*res);
      if (done) done(*res);
    }, true);
  });
  return id;
}

void session::write_object_sized(std::uint16_t index, std::uint8_t sub, std::int64_t value, unsigned size,
                                 std::shared_ptr<result> res, completion done) {
  std::vector<std::uint8_t> bytes;
  for (unsigned i = 0; i < size; ++i) bytes.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(value) >> (8 * i)));
  queue_download(index, sub, std::move(bytes), [this, index, sub, value, size, res, done](const transfer_result& r) {
    // The type is not known: the drive's answer says whether the size was short of its type.
    if (!r.ok && is_size_refusal(r.abort) && size < 8) {
      return write_object_sized(index, sub, value, size * 2, res, done);
    }
    res->size = size;
    if (!r.ok) {
      res->end = outcome::failed;
      res->abort = r.abort;
      res->error = "writing " + object_name(index, sub) + " as " + std::to_string(size) + " byte(s): " + transfer_failure(r);
      if (r.abort == sdo_abort::data_type_length_too_high) {
        res->error += "; the object is shorter: " + std::to_string(value) + " does not fit it";
      }
    }
    fill_result(*res);
    if (done) done(*res);
  });
}

}  // namespace cia402::axes
