#include "io/viewer.hpp"

#include <cstring>
#include <fstream>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

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
  using Json = nlohmann::ordered_json;  // keeps the keys in the order they are set
  Json data;
  data["title"] = title_;
  data["source"] = source_;
  data["particles"] = world.particles.size();
  data["times"] = times_;
  data["kinetic"] = kinetic_;
  data["potential"] = potential_;
  std::vector<double> total(kinetic_.size());
  for (size_t k = 0; k < total.size(); ++k)
    total[k] = kinetic_[k] + potential_[k];
  data["total"] = total;
  // Each surface as {"from": first frame, "triangles": [i, j, k, ...]}.
  data["surfaces"] = Json::array();
  for (const auto& [from, list] : surfaces_) {
    std::vector<Index> flat;
    for (const Triangle& t : list)
      flat.insert(flat.end(), t.begin(), t.end());
    Json surface;
    surface["from"] = from;
    surface["triangles"] = flat;
    data["surfaces"].push_back(std::move(surface));
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
  data["springs"] = springs;
  std::vector<Index> pins;
  for (Index i = 0; i < world.particles.size(); ++i) {
    if (world.particles.inv_m[i] == 0.0) pins.push_back(i);
  }
  data["pins"] = pins;
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
  data["frames"] = Json::array();
  for (const std::vector<float>& frame : positions_)
    data["frames"].push_back(base64(frame.data(), frame.size() * sizeof(float)));
  // A title or file name that is not valid UTF-8 gets U+FFFD where it is not, rather than no
  // page; "</" is escaped so that no string closes the page's <script> element.
  const std::string json =
      script_safe_json(data.dump(-1, ' ', false, Json::error_handler_t::replace));

  const std::string_view marker = "/*CLOTHLAB_DATA*/";
  const size_t at = kViewerTemplate.find(marker);
  if (at == std::string_view::npos) throw std::logic_error("viewer.html has no data marker");
  std::ofstream out(html, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", html.string()));
  out << kViewerTemplate.substr(0, at) << json << kViewerTemplate.substr(at + marker.size());
  if (!out) throw std::runtime_error(fmt::format("writing {} failed", html.string()));
}

}  // namespace clothlab
