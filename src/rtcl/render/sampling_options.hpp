// The names of the samplers and reconstruction filters of the distributed
// ray tracer (kernels/shared/sampling.h), for the command line and the
// benchmarks.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace rtcl {

enum class Sampler : std::uint32_t { stratified = 0, random = 1, sobol = 2 };  // RTCL_SAMPLER_*
enum class Filter : std::uint32_t { box = 0, gaussian = 1 };                   // RTCL_FILTER_*

std::string_view sampler_name(Sampler s);
std::string_view filter_name(Filter f);
// nullopt for an unknown name.
std::optional<Sampler> sampler_from_name(std::string_view name);
std::optional<Filter> filter_from_name(std::string_view name);
// "stratified, random, sobol" / "box, gaussian": for error messages.
std::string sampler_names();
std::string filter_names();

}  // namespace rtcl
