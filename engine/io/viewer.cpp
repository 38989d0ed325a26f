#include "io/viewer.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "io/files.hpp"
#include "io/json.hpp"

namespace clothlab {

extern const std::string_view kViewerTemplate;  // viewer.html, embedded at build time

namespace {

// Appends the base64 digits of `size` bytes to `out`.
void append_base64(std::string& out, const unsigned char* bytes, size_t size) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (size_t i = 0; i < size; i += 3) {
    // Three bytes make four 6-bit digits; a short last group is padded with '='.
    const unsigned a = bytes[i];
    const unsigned b = i + 1 < size ? bytes[i + 1] : 0;
    const unsigned c = i + 2 < size ? bytes[i + 2] : 0;
    const unsigned group = (a << 16) | (b << 8) | c;
    out += kDigits[(group >> 18) & 63];
    out += kDigits[(group >> 12) & 63];
    out += i + 1 < size ? kDigits[(group >> 6) & 63] : '=';
    out += i + 2 < size ? kDigits[group & 63] : '=';
  }
}

// The page's file, written through a buffer of 1 MiB: the page streams out in large writes,
// never held whole in memory, to a temporary file that replaces the page only when whole
// (io/files.hpp).
class PageFile {
 public:
  PageFile(const Folder& folder, const std::string& name) : file_(folder, name) {
    buffer_.reserve(kChunk + kChunk / 4);
  }

  void put(std::string_view text) {
    buffer_ += text;
    if (buffer_.size() >= kChunk) drain();
  }
  void put(Index i) {
    fmt::format_to(std::back_inserter(buffer_), "{}", i);
    if (buffer_.size() >= kChunk) drain();
  }
  // Writes out what is buffered and puts the page in place, on disk before it has the name.
  void finish() {
    drain();
    file_.commit(/*sync=*/true);
  }

  static constexpr size_t kChunk = 1 << 20;  // [bytes]

 private:
  void drain() {
    file_.write(buffer_);
    buffer_.clear();
  }

  ReplaceFile file_;
  std::string buffer_;
};

// Puts the base64 of a frame's floats as a JSON string, a piece at a time.
void put_frame(PageFile& file, const std::vector<float>& x, std::string& piece) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(x.data());
  const size_t size = x.size() * sizeof(float);
  constexpr size_t kPiece = 3 * (1 << 16);  // a multiple of 3: no padding but at the end
  file.put("\"");
  for (size_t at = 0; at < size; at += kPiece) {
    piece.clear();
    append_base64(piece, bytes + at, std::min(kPiece, size - at));
    file.put(piece);
  }
  file.put("\"");
}

// "2nd", "3rd", "12th", "21st".
std::string ordinal(long k) {
  const long tens = k % 100, units = k % 10;
  const char* suffix = (tens >= 11 && tens <= 13) ? "th"
                       : units == 1               ? "st"
                       : units == 2               ? "nd"
                       : units == 3               ? "rd"
                                                  : "th";
  return fmt::format("{}{}", k, suffix);
}

// "256 MiB", "11.4 MiB", "12 KiB", "96 bytes".
std::string bytes_text(long bytes) {
  constexpr long kKiB = 1024, kMiB = 1024 * 1024;
  if (bytes >= kMiB && bytes % kMiB == 0) return fmt::format("{} MiB", bytes / kMiB);
  if (bytes >= kMiB) return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / kMiB);
  if (bytes >= kKiB) return fmt::format("{:.0f} KiB", static_cast<double>(bytes) / kKiB);
  return fmt::format("{} bytes", bytes);
}

}  // namespace

ViewerRecorder::ViewerRecorder(std::string title, std::string source, long expected_frames,
                               long max_frames, long budget)
    : title_(std::move(title)),
      source_(std::move(source)),
      expected_frames_(expected_frames),
      max_frames_(max_frames),
      budget_(budget) {}

void ViewerRecorder::offer(const World& world) {
  const Matrix3X& x = world.particles.x;
  if (offered_ == 0) {
    // The page holds `limit_` frames: max_frames, fewer if they would pass the budget, and at
    // least the first and the last. The last needs a place of its own unless every frame is
    // kept, so the stride spreads the others over limit_ - 1 places.
    const long frame_bytes = std::max<long>(1, x.size() * static_cast<long>(sizeof(float)));
    limit_ = std::max(2L, std::min(max_frames_, budget_ / frame_bytes));
    stride_ = expected_frames_ <= limit_
                  ? 1
                  : (expected_frames_ + (limit_ - 1) - 1) / (limit_ - 1);  // rounded up
  }
  const long k = offered_++;
  // A run that offers more frames than expected finds every place taken; the last frame needs a
  // place of its own unless every frame is kept (a stride of 1).
  const auto full = [&] {
    return static_cast<long>(kept_.size()) >= (stride_ == 1 ? limit_ : limit_ - 1);
  };
  while (k % stride_ == 0 && full())
    thin_out();
  last_pending_ = k % stride_ != 0;
  Frame& frame = last_pending_ ? last_ : kept_.emplace_back();
  frame.x.assign(x.data(), x.data() + x.size());  // doubles -> floats
  frame.t = world.t;
  frame.kinetic = world.kinetic_energy();
  frame.potential = world.potential_energy();
  const bool differs =
      surfaces_.empty() || surfaces_.back().second.size() != world.triangles.size();
  if (!last_pending_ && differs) {
    surfaces_.emplace_back(static_cast<long>(kept_.size()) - 1, world.triangles);
  }
  last_surface_differs_ = last_pending_ && differs;
  if (last_surface_differs_) last_surface_ = world.triangles;
}

void ViewerRecorder::thin_out() {
  // Kept frame j (offered frame j * stride) stays when j is even, as kept frame j / 2. A
  // surface from kept frame j on is shown from the next one that stays, j / 2 rounded up; of
  // two that land on the same frame the later one wins.
  for (size_t j = 1; 2 * j < kept_.size(); ++j)
    kept_[j] = std::move(kept_[2 * j]);
  kept_.resize((kept_.size() + 1) / 2);
  std::vector<std::pair<long, std::vector<Triangle>>> surfaces;
  for (auto& [from, list] : surfaces_) {
    const long to = (from + 1) / 2;
    if (!surfaces.empty() && surfaces.back().first == to) surfaces.pop_back();
    surfaces.emplace_back(to, std::move(list));
  }
  surfaces_ = std::move(surfaces);
  stride_ *= 2;
}

void ViewerRecorder::stopped(std::string message, long step, Index particle) {
  stop_ = Stop{std::move(message), step, particle};
}

long ViewerRecorder::frames_kept() const {
  return static_cast<long>(kept_.size()) + (last_pending_ ? 1 : 0);
}

std::string ViewerRecorder::sampling_note() const {
  if (frames_kept() == offered_) return "";
  const long frame_bytes = static_cast<long>(kept_.front().x.size() * sizeof(float));
  const std::string which = kept_.size() == 1 ? "the first frame"
                            : stride_ == 2    ? "every other frame"
                                              : "every " + ordinal(stride_) + " frame";
  const std::string why = budget_ / std::max(1L, frame_bytes) < max_frames_
                              ? fmt::format("a page holds at most {} of frames, {} each",
                                            bytes_text(budget_), bytes_text(frame_bytes))
                              : fmt::format("a page holds at most {} frames", max_frames_);
  return fmt::format("the page keeps {} and the last ({} of {}): {}", which, frames_kept(),
                     offered_, why);
}

namespace {

// Calls visit(set, k, structural) for each spring of each spring family of `world` in turn,
// with a comma put between them: structural for the family "springs", not for "bending".
template <typename Visit>
void put_springs(PageFile& file, const World& world, Visit visit) {
  bool first = true;
  for (const auto& effect : world.force_effects) {
    if (const auto* family = dynamic_cast<const SpringDampers*>(effect.get())) {
      const bool structural = family->name() == "springs";
      for (size_t k = 0; k < family->springs().size(); ++k) {
        if (!first) file.put(",");
        first = false;
        visit(family->springs(), k, structural);
      }
    }
  }
}

}  // namespace

void ViewerRecorder::write(const World& world, const std::filesystem::path& html) const {
  write(world, Folder::holding(html), html.filename().string());
}

void ViewerRecorder::write(const World& world, const Folder& folder,
                           const std::string& name) const {
  // The frames of the page: those kept, then the last one offered if it is not among them.
  std::vector<const Frame*> frames;
  for (const Frame& frame : kept_)
    frames.push_back(&frame);
  if (last_pending_) frames.push_back(&last_);
  std::vector<double> times, kinetic, potential;
  for (const Frame* frame : frames) {
    times.push_back(frame->t);
    kinetic.push_back(frame->kinetic);
    potential.push_back(frame->potential);
  }

  // The small part of the data through the JSON library; the mesh and the frames, which may be
  // hundreds of megabytes, are streamed to the file below, keys of the same object.
  using Json = nlohmann::ordered_json;  // keeps the keys in the order they are set
  Json data;
  data["title"] = title_;
  data["source"] = source_;
  data["particles"] = world.particles.size();
  data["sampling"] = sampling_note();
  data["times"] = times;
  data["kinetic"] = kinetic;
  data["potential"] = potential;
  if (stop_) {
    data["stopped"] = {{"message", stop_->message}, {"step", stop_->step}};
    data["stopped"]["particle"] = stop_->particle >= 0 ? Json(stop_->particle) : Json(nullptr);
  }
  // Colliders, drawn so that a student sees what the cloth lies on.
  data["colliders"] = Json::array();
  for (const auto& effect : world.post_step_effects) {
    Json collider;
    if (const auto* g = dynamic_cast<const Ground*>(effect.get())) {
      collider["type"] = "ground";
      collider["y"] = g->y0();
    } else if (const auto* b = dynamic_cast<const Sphere*>(effect.get())) {
      collider["type"] = "sphere";
      collider["centre"] = {b->centre().x(), b->centre().y(), b->centre().z()};
      collider["radius"] = b->radius();
    } else if (const auto* plane = dynamic_cast<const Plane*>(effect.get())) {
      collider["type"] = "plane";
      collider["point"] = {plane->point().x(), plane->point().y(), plane->point().z()};
      collider["normal"] = {plane->normal().x(), plane->normal().y(), plane->normal().z()};
    } else {
      continue;
    }
    data["colliders"].push_back(std::move(collider));
  }
  // A title or file name that is not valid UTF-8 gets U+FFFD where it is not, rather than no
  // page; every <, > and & is escaped so that no string closes the page's <script> element.
  // The streamed part is numbers and base64 digits, which hold none of the three.
  std::string head = script_safe_json(data.dump(-1, ' ', false, Json::error_handler_t::replace));
  head.pop_back();  // the closing '}': the object goes on below

  const std::string_view marker = "/*CLOTHLAB_DATA*/";
  const size_t at = kViewerTemplate.find(marker);
  if (at == std::string_view::npos) throw std::logic_error("viewer.html has no data marker");

  {
    PageFile file(folder, name);
    file.put(kViewerTemplate.substr(0, at));
    file.put(head);
    // Each surface as {"from": first frame, "triangles": [i, j, k, ...]}, the last frame's
    // after those of the kept frames when it differs from them.
    std::vector<std::pair<long, const std::vector<Triangle>*>> surfaces;
    for (const auto& [from, list] : surfaces_)
      surfaces.emplace_back(from, &list);
    if (last_surface_differs_) {
      surfaces.emplace_back(static_cast<long>(frames.size()) - 1, &last_surface_);
    }
    file.put(",\"surfaces\":[");
    for (size_t k = 0; k < surfaces.size(); ++k) {
      file.put(k == 0 ? "{\"from\":" : ",{\"from\":");
      file.put(static_cast<Index>(surfaces[k].first));
      file.put(",\"triangles\":[");
      bool first = true;
      for (const Triangle& t : *surfaces[k].second) {
        for (const Index i : t) {
          if (!first) file.put(",");
          first = false;
          file.put(i);
        }
      }
      file.put("]}");
    }
    file.put("]");
    file.put(",\"springs\":[");
    put_springs(file, world, [&](const SpringSet& s, size_t k, bool) {
      file.put(s.i(k));
      file.put(",");
      file.put(s.j(k));
    });
    // Each spring's rest length, for colouring the cloth by strain: null for a spring the
    // colours leave out (the bending springs, squeezed by every fold).
    file.put("],\"rest\":[");
    put_springs(file, world, [&](const SpringSet& s, size_t k, bool structural) {
      file.put(structural ? fmt::format("{}", s.l0(k)) : std::string("null"));
    });
    file.put("],\"pins\":[");
    bool first = true;
    for (Index i = 0; i < world.particles.size(); ++i) {
      if (world.particles.inv_m[i] != 0.0) continue;
      if (!first) file.put(",");
      first = false;
      file.put(i);
    }
    file.put("],\"frames\":[");
    std::string piece;
    for (size_t f = 0; f < frames.size(); ++f) {
      if (f > 0) file.put(",");
      put_frame(file, frames[f]->x, piece);
    }
    file.put("]}");
    file.put(kViewerTemplate.substr(at + marker.size()));
    file.finish();
  }
}

}  // namespace clothlab
