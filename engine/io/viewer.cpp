#include "io/viewer.hpp"

#include <cstring>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "io/json.hpp"

namespace clothlab {

extern const std::string_view kViewerTemplate;  // viewer.html, embedded at build time

namespace {

std::string base64(const void* data, size_t size) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
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
  return out;
}

template <class T>
std::string json_array(const std::vector<T>& values) {
  return fmt::format("[{}]", fmt::join(values, ","));
}

}  // namespace

ViewerRecorder::ViewerRecorder(std::string title, std::string source, long expected_frames,
                               long max_frames)
    : title_(std::move(title)), source_(std::move(source)) {
  stride_ = std::max(1L, (expected_frames + max_frames - 1) / max_frames);
}

void ViewerRecorder::offer(const World& world) {
  if (offered_++ % stride_ != 0) return;
  const Matrix3X& x = world.particles.x;
  positions_.emplace_back(x.data(), x.data() + x.size());  // doubles -> floats
  if (surfaces_.empty() || surfaces_.back().second.size() != world.triangles.size()) {
    surfaces_.emplace_back(static_cast<long>(times_.size()), world.triangles);
  }
  times_.push_back(world.t);
  kinetic_.push_back(world.kinetic_energy());
  potential_.push_back(world.potential_energy());
}

void ViewerRecorder::write(const World& world, const std::filesystem::path& html) const {
  // Each surface as {"from": first frame, "triangles": [i, j, k, ...]}.
  std::string surfaces;
  for (const auto& [from, list] : surfaces_) {
    std::vector<Index> flat;
    for (const Triangle& t : list)
      flat.insert(flat.end(), t.begin(), t.end());
    if (!surfaces.empty()) surfaces += ",";
    surfaces += fmt::format("{{\"from\":{},\"triangles\":{}}}", from, json_array(flat));
  }
  std::vector<Index> springs;
  for (const auto& effect : world.force_effects) {
    if (const auto* s = dynamic_cast<const SpringDampers*>(effect.get())) {
      for (size_t k = 0; k < s->springs().size(); ++k) {
        springs.push_back(s->springs().i(k));
        springs.push_back(s->springs().j(k));
      }
    }
  }
  // Colliders, drawn so that a student sees what the cloth lies on.
  std::string colliders;
  for (const auto& effect : world.post_step_effects) {
    if (!colliders.empty()) colliders += ",";
    if (const auto* g = dynamic_cast<const Ground*>(effect.get())) {
      colliders += fmt::format("{{\"type\":\"ground\",\"y\":{}}}", g->y0());
    } else if (const auto* b = dynamic_cast<const Sphere*>(effect.get())) {
      colliders += fmt::format("{{\"type\":\"sphere\",\"centre\":[{},{},{}],\"radius\":{}}}",
                               b->centre().x(), b->centre().y(), b->centre().z(), b->radius());
    } else if (!colliders.empty()) {
      colliders.pop_back();
    }
  }
  std::vector<Index> pins;
  for (Index i = 0; i < world.particles.size(); ++i) {
    if (world.particles.inv_m[i] == 0.0) pins.push_back(i);
  }
  std::vector<double> total(kinetic_.size());
  for (size_t k = 0; k < total.size(); ++k)
    total[k] = kinetic_[k] + potential_[k];

  std::string frames = "[";
  for (const std::vector<float>& frame : positions_) {
    if (frames.size() > 1) frames += ",";
    frames += '"';
    frames += base64(frame.data(), frame.size() * sizeof(float));
    frames += '"';
  }
  frames += "]";
  const std::string json = fmt::format(
      "{{\"title\":{},\"source\":{},\"particles\":{},\"times\":{},\"kinetic\":{},"
      "\"potential\":{},\"total\":{},\"surfaces\":[{}],\"springs\":{},\"pins\":{},\"colliders\":[{}"
      "]"
      ","
      "\"frames\":{}}}",
      json_string(title_), json_string(source_), world.particles.size(), json_array(times_),
      json_array(kinetic_), json_array(potential_), json_array(total), surfaces,
      json_array(springs), json_array(pins), colliders, frames);

  const std::string_view marker = "/*CLOTHLAB_DATA*/";
  const size_t at = kViewerTemplate.find(marker);
  if (at == std::string_view::npos) throw std::logic_error("viewer.html has no data marker");
  std::ofstream out(html, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", html.string()));
  out << kViewerTemplate.substr(0, at) << json << kViewerTemplate.substr(at + marker.size());
  if (!out) throw std::runtime_error(fmt::format("writing {} failed", html.string()));
}

}  // namespace clothlab
