// The words the scene format uses for each enum of sim/scene/scene.h, in one table per enum
// (EnumWords<E>::table). The scene reader takes its choices and decodes from these tables,
// and whatever prints a setting back (stats.json, run.json, messages) names it with word_of,
// so a word is written once.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sim/scene/scene.h"

namespace shellmpm {

/// One word of an enum's table.
template <class E>
struct Word {
  std::string_view text;
  E value;
};

/// Specialised below for every enum the scene format spells out.
template <class E>
struct EnumWords;

#define SHELLMPM_ENUM_WORDS(E, N, ...)                            \
  template <>                                                     \
  struct EnumWords<E> {                                           \
    static constexpr std::array<Word<E>, N> table{{__VA_ARGS__}}; \
  }

SHELLMPM_ENUM_WORDS(Transfer, 2, {"apic", Transfer::Apic}, {"mls", Transfer::Mls});
SHELLMPM_ENUM_WORDS(Integrator, 3, {"explicit", Integrator::Explicit},
                    {"implicit", Integrator::Implicit}, {"auto", Integrator::Auto});
SHELLMPM_ENUM_WORDS(ImplicitPreconditioner, 2, {"factorised", ImplicitPreconditioner::Factorised},
                    {"block_jacobi", ImplicitPreconditioner::BlockJacobi});
SHELLMPM_ENUM_WORDS(Quality, 4, {"draft", Quality::Draft}, {"preview", Quality::Preview},
                    {"production", Quality::Production}, {"final", Quality::Final});
SHELLMPM_ENUM_WORDS(ShellVelocities, 2, {"per_shell", ShellVelocities::PerShell},
                    {"shared", ShellVelocities::Shared});
SHELLMPM_ENUM_WORDS(ContactAt, 2, {"surface", ContactAt::Surface}, {"stencil", ContactAt::Stencil});
SHELLMPM_ENUM_WORDS(ShotSettings::OnIntegrityFailure, 2,
                    {"warn", ShotSettings::OnIntegrityFailure::Warn},
                    {"stop", ShotSettings::OnIntegrityFailure::Stop});
SHELLMPM_ENUM_WORDS(ShotSettings::OnEnergyGain, 3, {"ignore", ShotSettings::OnEnergyGain::Ignore},
                    {"warn", ShotSettings::OnEnergyGain::Warn},
                    {"stop", ShotSettings::OnEnergyGain::Stop});
SHELLMPM_ENUM_WORDS(MaterialKind, 3, {"elastic", MaterialKind::Elastic},
                    {"sand", MaterialKind::Sand}, {"snow", MaterialKind::Snow});
SHELLMPM_ENUM_WORDS(ElasticModel, 2, {"fixed_corotated", ElasticModel::FixedCorotated},
                    {"neo_hookean", ElasticModel::NeoHookean});
SHELLMPM_ENUM_WORDS(ShapeDesc::Kind, 5, {"plane", ShapeDesc::Kind::Plane},
                    {"box", ShapeDesc::Kind::Box}, {"sphere", ShapeDesc::Kind::Sphere},
                    {"cylinder", ShapeDesc::Kind::Cylinder}, {"mesh", ShapeDesc::Kind::Mesh});
SHELLMPM_ENUM_WORDS(BoundaryKind, 3, {"sticky", BoundaryKind::Sticky}, {"slip", BoundaryKind::Slip},
                    {"separate", BoundaryKind::Separate});
SHELLMPM_ENUM_WORDS(ShellDesc::Kind, 4, {"sheet", ShellDesc::Kind::Sheet},
                    {"cylinder", ShellDesc::Kind::Cylinder}, {"sphere", ShellDesc::Kind::Sphere},
                    {"mesh", ShellDesc::Kind::Mesh});
SHELLMPM_ENUM_WORDS(ShellDesc::Contact, 3, {"auto", ShellDesc::Contact::Auto},
                    {"on", ShellDesc::Contact::On}, {"off", ShellDesc::Contact::Off});
SHELLMPM_ENUM_WORDS(PrerollSettings::Method, 2, {"static", PrerollSettings::Method::Static},
                    {"dynamic", PrerollSettings::Method::Dynamic});
SHELLMPM_ENUM_WORDS(MeshFormat, 3, {"ply", MeshFormat::Ply}, {"obj", MeshFormat::Obj},
                    {"glb", MeshFormat::Glb});
SHELLMPM_ENUM_WORDS(UpAxis, 2, {"y", UpAxis::Y}, {"z", UpAxis::Z});
SHELLMPM_ENUM_WORDS(RendererKind, 2, {"raster", RendererKind::Raster},
                    {"raytrace", RendererKind::Raytrace});
SHELLMPM_ENUM_WORDS(BulkDraw, 5, {"auto", BulkDraw::Auto}, {"volume", BulkDraw::Volume},
                    {"surface", BulkDraw::Surface}, {"particles", BulkDraw::Particles},
                    {"none", BulkDraw::None});

#undef SHELLMPM_ENUM_WORDS

/// The scene-format word of `value` ("apic", "raytrace").
template <class E>
std::string word_of(E value) {
  for (const Word<E>& w : EnumWords<E>::table)
    if (w.value == value) return std::string(w.text);
  return "?";
}

/// The value a word names, or nothing when it names none.
template <class E>
std::optional<E> enum_of_word(std::string_view text) {
  for (const Word<E>& w : EnumWords<E>::table)
    if (w.text == text) return w.value;
  return std::nullopt;
}

/// Every word of E, in table order (the order the docs list them).
template <class E>
std::vector<std::string> words_of() {
  std::vector<std::string> out;
  for (const Word<E>& w : EnumWords<E>::table) out.emplace_back(w.text);
  return out;
}

}  // namespace shellmpm
