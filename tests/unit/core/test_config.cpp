// Configuration: defaults, overrides, and one-line errors naming the key for bad input.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/config.hpp"
#include "core/error.hpp"

using namespace sphdisk;

namespace {
std::string error_of(const std::string& toml, const std::vector<std::string>& overrides = {}) {
  try {
    parse_config(toml, "test.toml", overrides);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Config, DefaultsAreThePaperRing) {
  const Config c = parse_config("", "test.toml", {});
  EXPECT_EQ(c.particles, 10000);
  EXPECT_DOUBLE_EQ(c.tau_start, 0.018);
  EXPECT_EQ(c.output_tau, (std::vector<double>{0.036, 0.054, 0.072, 0.090, 0.126}));
  EXPECT_DOUBLE_EQ(c.viscosity, 3e-8);
}

TEST(Config, FileValuesAndOverrides) {
  const Config c = parse_config("[problem]\nparticles = 500\n[integrator]\nscheme = \"rk45\"\n", "test.toml",
                                {"problem.particles=100000", "output.tau=[0.036, 0.09]", "integrator.tolerance=1e-7",
                                 "sph.kernel=wendland_c2"});
  EXPECT_EQ(c.particles, 100000);
  EXPECT_EQ(c.scheme, "rk45");
  EXPECT_EQ(c.output_tau, (std::vector<double>{0.036, 0.09}));
  EXPECT_DOUBLE_EQ(c.tolerance, 1e-7);
  EXPECT_EQ(c.kernel, "wendland_c2");  // a bare word on --set is a string
}

TEST(Config, ResolvedConfigurationListsEveryKey) {
  const Config c = parse_config("", "test.toml", {"problem.particles=123"});
  EXPECT_NE(c.resolved_toml.find("particles = 123"), std::string::npos);
  EXPECT_NE(c.resolved_toml.find("[integrator]"), std::string::npos);
  // Re-parsing the resolved configuration gives the same configuration.
  const Config again = parse_config(c.resolved_toml, "resolved.toml", {});
  EXPECT_EQ(again.resolved_toml, c.resolved_toml);
}

TEST(Config, UnknownKeyIsNamedWithASuggestion) {
  const std::string e = error_of("[problem]\nparticle = 5\n");
  EXPECT_NE(e.find("unknown key 'problem.particle'"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'problem.particles'"), std::string::npos) << e;
}

TEST(Config, InvalidValuesNameKeyAndAllowedRange) {
  EXPECT_NE(error_of("[problem]\nparticles = 0\n").find("problem.particles must be an integer in [1,"), std::string::npos);
  EXPECT_NE(error_of("[problem]\nparticles = -5\n").find("problem.particles"), std::string::npos);
  EXPECT_NE(error_of("[problem]\nparticles = \"many\"\n").find("problem.particles must be an integer"), std::string::npos);
  EXPECT_NE(error_of("[physics]\nviscosity = -1.0\n").find("physics.viscosity must be >= 0"), std::string::npos);
  EXPECT_NE(error_of("[integrator]\ntolerance = 0.0\n").find("integrator.tolerance must be in"), std::string::npos);
  EXPECT_NE(error_of("[integrator]\nscheme = \"euler\"\n").find("must be one of \"block\" \"leapfrog\" \"respa\" \"rk45\""), std::string::npos);
  EXPECT_NE(error_of("[output]\ntau = [0.09, 0.05]\n").find("output.tau must be strictly increasing"), std::string::npos);
  EXPECT_NE(error_of("[output]\ntau = [0.01]\n").find("output.tau must start after problem.tau_start"), std::string::npos);
  EXPECT_NE(error_of("[physics]\naccretion_radius = 1.5\n").find("physics.accretion_radius"), std::string::npos);
  EXPECT_NE(error_of("[physics]\neos = \"isothermal\"\n").find("physics.sound_speed"), std::string::npos);
}

TEST(Config, MalformedTomlGivesLineAndColumn) {
  const std::string e = error_of("[problem]\nparticles = = 3\n");
  EXPECT_NE(e.find("test.toml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("invalid TOML"), std::string::npos) << e;
}

TEST(Config, BadOverrideSyntax) {
  EXPECT_NE(error_of("", {"problem.particles"}).find("expected section.key=value"), std::string::npos);
  EXPECT_NE(error_of("", {"problem.nonsense=3"}).find("unknown key 'problem.nonsense'"), std::string::npos);
}

TEST(Config, ErrorsAreOneLine) {
  for (const std::string& e : {error_of("[problem]\nparticle = 5\n"), error_of("[problem]\nparticles = = 3\n"),
                               error_of("[output]\ntau = [0.09, 0.05]\n")}) {
    ASSERT_FALSE(e.empty());
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(Config, MissingFileIsAUserError) {
  EXPECT_THROW(load_config("/nonexistent/ring.toml", {}), UserError);
}

// An initial-conditions path in a configuration file is taken from that file's directory, one on
// the command line from the current directory; both are stored absolute, absolute ones as given.
TEST(Config, InitialConditionsPathRelativeToItsSource) {
  const std::string cwd = std::filesystem::current_path().string();
  EXPECT_EQ(parse_config("problem.initial_conditions = \"ic/a.hdf5\"\n", "/data/set/x.toml", {}, "/data/set").initial_conditions,
            "/data/set/ic/a.hdf5");
  EXPECT_EQ(parse_config("problem.initial_conditions = \"../a.hdf5\"\n", "/data/set/x.toml", {}, "/data/set").initial_conditions,
            "/data/a.hdf5");
  EXPECT_EQ(parse_config("problem.initial_conditions = \"/abs/a.hdf5\"\n", "x.toml", {}, "/data/set").initial_conditions,
            "/abs/a.hdf5");
  const Config set = parse_config("problem.initial_conditions = \"a.hdf5\"\n", "/data/set/x.toml",
                                  {"problem.initial_conditions=\"b.hdf5\""}, "/data/set");
  EXPECT_EQ(set.initial_conditions, (std::filesystem::path(cwd) / "b.hdf5").string());
  EXPECT_NE(set.resolved_toml.find("initial_conditions = \"" + set.initial_conditions + "\""), std::string::npos);
  // Text without a directory (a checkpoint's stored configuration) keeps its path as written.
  EXPECT_EQ(parse_config("problem.initial_conditions = \"a.hdf5\"\n", "checkpoint.hdf5", {}).initial_conditions, "a.hdf5");
  EXPECT_EQ(parse_config("", "x.toml", {}, "/data/set").initial_conditions, "");
}

// Strings open only where TOML lets them begin; quoted text (non-ASCII included) elsewhere is
// refused before toml++ sees it (fuzz-found undefined behaviour: tests/fuzz_regressions/), while
// strings after '=', '[', ',', '{', a line start or a dotted key's '.' still parse.
TEST(Config, QuotesOnlyWhereStringsMayBegin) {
  for (const std::string bad : {"[output]\ntau = [0.03e'\xc3\x96']\n", "[output]\ndir = 1.'x'\n", "[output]\ndir = x\"y\"\n"})
    EXPECT_NE(error_of(bad).find("inside a bare value"), std::string::npos) << bad;
  EXPECT_EQ(error_of("[output]\ndir = 'runs/\xc3\xa9t\xc3\xa9' # \xc3\xa9\n\"tau\" = [ 0.05,\n  0.09 ]\n"), "");
  EXPECT_EQ(error_of("output.dir = \"runs/x\"\nproblem.'seed' = 3\n"), "");
}

// A retired key (docs/design.md, "Modes kept and retired") with the value that means what the code
// now always does is accepted, as older checkpoints record it; any other value names the replacement.
TEST(Config, RetiredKeysAcceptTheirInertValueAndRefuseOthers) {
  EXPECT_EQ(error_of("[sph]\nlist_skin = 0.0\n"), "");
  EXPECT_EQ(error_of("", {"sph.list_skin=0"}), "");
  const std::string e = error_of("[sph]\nlist_skin = 0.2\n");
  EXPECT_NE(e.find("sph.list_skin was retired: neighbour lists are built anew"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_NE(error_of("", {"sph.list_skin=0.3"}).find("was retired"), std::string::npos);
  EXPECT_EQ(parse_config("", "test.toml", {}).resolved_toml.find("list_skin"), std::string::npos);
}

// A retired value of a kept key is refused in one line naming the replacement; a stored
// configuration holding it (a checkpoint's) parses with an override naming the replacement.
TEST(Config, RetiredValuesNameTheirReplacement) {
  const std::string e = error_of("[integrator]\nscheme = \"rk23\"\n");
  EXPECT_NE(e.find("integrator.scheme = \"rk23\" was retired: rk45 reaches the same accuracy"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_NE(error_of("", {"integrator.scheme=rk23"}).find("was retired"), std::string::npos);
  EXPECT_EQ(error_of("[integrator]\nscheme = \"rk23\"\n", {"integrator.scheme=\"rk45\""}), "");
  EXPECT_EQ(parse_config("[integrator]\nscheme = \"rk23\"\n", "stored", {"integrator.scheme=rk45"}).scheme, "rk45");
}

// The locally isothermal equation of state names its sound speed at r0 and the power-law index.
TEST(Config, LocallyIsothermalNeedsItsSoundSpeed) {
  const Config c = parse_config("[physics]\neos = \"locally_isothermal\"\nsound_speed = 2.0\nsound_speed_index = 0.25\n",
                                "test.toml", {});
  EXPECT_DOUBLE_EQ(c.sound_speed_index, 0.25);
  EXPECT_NE(error_of("[physics]\neos = \"locally_isothermal\"\n").find("physics.eos = \"locally_isothermal\" needs physics.sound_speed > 0"),
            std::string::npos);
  EXPECT_NE(error_of("[physics]\nsound_speed_index = 3.0\n").find("physics.sound_speed_index must be in"), std::string::npos);
}

// An alpha viscosity needs a sound speed, replaces the constant viscosity and has no viscous time.
TEST(Config, ThreeDimensionsNeedPressureAndOneSoundSpeed) {
  const std::string lis = "[physics]\neos = \"locally_isothermal\"\n";
  EXPECT_EQ(error_of("[sph]\ndimension = 3\n" + lis + "aspect_ratio = 0.05\n"), "");
  EXPECT_NE(error_of("[sph]\ndimension = 3\n").find("sph.dimension = 3 needs pressure"), std::string::npos);
  EXPECT_NE(error_of(lis + "aspect_ratio = 0.05\nsound_speed = 20.0\n").find("give the sound speed once"), std::string::npos);
  EXPECT_NE(error_of(lis).find("physics.aspect_ratio > 0"), std::string::npos);
  EXPECT_NE(error_of("[physics]\naspect_ratio = 0.05\n").find("sets the sound speed of an equation of state"), std::string::npos);
  EXPECT_NE(error_of("[physics]\nav_alpha = 0.1\n").find("physics.av_alpha > 0 needs a sound speed"), std::string::npos);
  EXPECT_EQ(error_of(lis + "aspect_ratio = 0.05\nav_alpha = 0.1\nav_limiter = \"none\"\n"), "");
  EXPECT_NE(error_of("[physics]\neos = \"isothermal\"\naspect_ratio = 1.5\n").find("physics.aspect_ratio"), std::string::npos);
}

TEST(Config, DiscNeedsOrderedEdgesAnInnerAccretionRadiusAndOutputTimes) {
  const std::string disc = "[problem]\ntype = \"disc\"\n";
  EXPECT_EQ(error_of(disc + "[output]\norbits = [1.0]\n"), "");
  EXPECT_NE(error_of(disc).find("a disc has no viscous time tau"), std::string::npos);
  EXPECT_NE(error_of(disc + "inner_radius = 5.0\nouter_radius = 1.0\n[output]\norbits = [1.0]\n").find("must be below problem.outer_radius"),
            std::string::npos);
  EXPECT_NE(error_of(disc + "inner_radius = 0.5\n[output]\norbits = [1.0]\n[physics]\naccretion_radius = 0.6\n")
                .find("must be below problem.inner_radius"),
            std::string::npos);
}

TEST(Config, AlphaViscosityNeedsASoundSpeedAndOutputTimes) {
  const std::string lis = "[physics]\neos = \"locally_isothermal\"\nsound_speed = 20.0\nviscosity = 0.0\nalpha_ss = 0.01\n";
  EXPECT_EQ(error_of(lis + "[output]\norbits = [1.0]\n"), "");
  EXPECT_NE(error_of(lis).find("there is no viscous time tau; give output.times or output.orbits"), std::string::npos);
  EXPECT_NE(error_of("[physics]\nalpha_ss = 0.01\nviscosity = 0.0\n[output]\norbits = [1.0]\n").find("needs a sound speed"),
            std::string::npos);
  EXPECT_NE(error_of("[physics]\neos = \"isothermal\"\nsound_speed = 20.0\nalpha_ss = 0.01\n[output]\norbits = [1.0]\n")
                .find("replaces physics.viscosity"),
            std::string::npos);
}

TEST(Config, BulkViscosityGivenOnce) {
  EXPECT_EQ(error_of("[physics]\nbulk_viscosity_ratio = 1.0\n"), "");
  EXPECT_NE(error_of("[physics]\nbulk_viscosity = 3e-8\nbulk_viscosity_ratio = 1.0\n").find("give the bulk viscosity once"),
            std::string::npos);
  EXPECT_NE(error_of("[physics]\nbulk_viscosity_ratio = -1.0\n").find("physics.bulk_viscosity_ratio must be in"),
            std::string::npos);
}

TEST(Config, AutoViscousUpdateIsSuperStepsForBlockStepsWithAConstantViscosity) {
  auto update = [](const std::string& text) { return parse_config(text, "test.toml", {}).resolved_viscous_update(); };
  const std::string block = "[integrator]\nscheme = \"block\"\n";
  EXPECT_EQ(update(block), "super_steps");  // pressureless
  EXPECT_EQ(update(block + "[physics]\neos = \"locally_isothermal\"\nsound_speed = 20.0\n"), "super_steps");
  EXPECT_EQ(update(block + "[physics]\neos = \"isothermal\"\nsound_speed = 20.0\nav_alpha = 1.0\n"), "explicit");
  EXPECT_EQ(update(block + "[physics]\neos = \"locally_isothermal\"\nsound_speed = 20.0\nviscosity = 0.0\nalpha_ss = 0.01\n"
                           "[output]\norbits = [1.0]\n"),
            "explicit");
  EXPECT_EQ(update("[integrator]\nscheme = \"leapfrog\"\n"), "explicit");
  EXPECT_EQ(update(block + "viscous_update = \"explicit\"\n[physics]\neos = \"isothermal\"\nsound_speed = 20.0\n"), "explicit");
}

TEST(Config, AutoNeighboursFollowTheParticleNumberIn2D) {
  const Config c = parse_config("", "test.toml", {});
  EXPECT_TRUE(c.neighbours_auto());
  EXPECT_NE(c.resolved_toml.find("neighbours = \"auto\""), std::string::npos);
  EXPECT_DOUBLE_EQ(auto_neighbours(2, 1000), 60);  // never below 60
  EXPECT_DOUBLE_EQ(auto_neighbours(2, 10000), 60);
  EXPECT_DOUBLE_EQ(auto_neighbours(2, 20000), 85);   // 60 sqrt(2) = 84.85
  EXPECT_DOUBLE_EQ(auto_neighbours(2, 30000), 104);  // 60 sqrt(3) = 103.92
  EXPECT_DOUBLE_EQ(auto_neighbours(2, 40000), 120);
  EXPECT_DOUBLE_EQ(auto_neighbours(2, 1e7), 120);    // never above 120
  EXPECT_DOUBLE_EQ(auto_neighbours(3, 1e6), 60);

  // Resolved: the number in every field and in the text that outputs and checkpoints record.
  const Config r = with_neighbours_resolved(parse_config("[problem]\nparticles = 30000\n", "test.toml", {}), 30000);
  EXPECT_FALSE(r.neighbours_auto());
  EXPECT_DOUBLE_EQ(r.neighbours, 104);
  EXPECT_NE(r.resolved_toml.find("neighbours = 104.0"), std::string::npos);
  EXPECT_EQ(r.particles, 30000);
  // A number given is kept whatever N is.
  EXPECT_DOUBLE_EQ(with_neighbours_resolved(parse_config("", "test.toml", {"sph.neighbours=57.9"}), 1e6).neighbours, 57.9);
  EXPECT_NE(error_of("", {"sph.neighbours=many"}).find("must be a number in [4, 10000] or \"auto\""), std::string::npos);
  EXPECT_NE(error_of("[sph]\nneighbours = true\n").find("or \"auto\""), std::string::npos);
}
