#include "rtcl/render/sampling_options.hpp"

#include <array>
#include <utility>

#include "rtcl/render/render_layouts.hpp"

namespace rtcl {

namespace {

static_assert(static_cast<std::uint32_t>(Sampler::stratified) == RTCL_SAMPLER_STRATIFIED &&
              static_cast<std::uint32_t>(Sampler::random) == RTCL_SAMPLER_RANDOM &&
              static_cast<std::uint32_t>(Sampler::sobol) == RTCL_SAMPLER_SOBOL);
static_assert(static_cast<std::uint32_t>(Filter::box) == RTCL_FILTER_BOX &&
              static_cast<std::uint32_t>(Filter::gaussian) == RTCL_FILTER_GAUSSIAN);

constexpr std::array<std::pair<Sampler, std::string_view>, 3> kSamplers{
    {{Sampler::stratified, "stratified"}, {Sampler::random, "random"}, {Sampler::sobol, "sobol"}}};
constexpr std::array<std::pair<Filter, std::string_view>, 2> kFilters{
    {{Filter::box, "box"}, {Filter::gaussian, "gaussian"}}};

template <class Table, class Key>
std::string_view name_of(const Table& table, Key key) {
  for (const auto& [k, name] : table)
    if (k == key) return name;
  return "?";
}

template <class Key, class Table>
std::optional<Key> from_name(const Table& table, std::string_view name) {
  for (const auto& [k, n] : table)
    if (n == name) return k;
  return std::nullopt;
}

template <class Table>
std::string names(const Table& table) {
  std::string out;
  for (const auto& entry : table) out += (out.empty() ? "" : ", ") + std::string(entry.second);
  return out;
}

}  // namespace

std::string_view sampler_name(Sampler s) { return name_of(kSamplers, s); }
std::string_view filter_name(Filter f) { return name_of(kFilters, f); }
std::optional<Sampler> sampler_from_name(std::string_view name) { return from_name<Sampler>(kSamplers, name); }
std::optional<Filter> filter_from_name(std::string_view name) { return from_name<Filter>(kFilters, name); }
std::string sampler_names() { return names(kSamplers); }
std::string filter_names() { return names(kFilters); }

}  // namespace rtcl
