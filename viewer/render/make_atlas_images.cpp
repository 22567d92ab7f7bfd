// simgrass-atlas: writes the procedural tuft atlas and ground texture as PNGs
// (OUTDIR/tuft-atlas.png, OUTDIR/ground-texture.png), e.g. for docs/images.
#include <CLI/CLI.hpp>
#include <charconv>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "replay/cli/option_checks.h"
#include "sim/scenario/json_bounds.h"
#include "viewer/render/atlas.h"

int main(int argc, char** argv) {
  // As simgrass: a file-size limit is a failed write reported below, not SIGXFSZ mid-PNG.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"Writes the procedural tuft atlas (tuft-atlas.png) and ground texture (ground-texture.png) into OUTDIR",
               "simgrass-atlas"};
  std::string outDir;
  int variants = 4;
  uint64_t seed = 1;
  std::string seedText = "1";
  app.add_option("OUTDIR", outDir, "Directory to write the PNGs into (created if missing)")->required();
  app.add_option("--variants", variants, "Grass tuft variants (atlas columns, plus the marking tuft)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  // Read as text and converted exactly: CLI11's unsigned conversion wraps "-1" and clamps values
  // past 2^64 - 1, which then drew the atlas of another seed without a word.
  app.add_option("--seed", seedText, "Seed of the procedural generation, 0 .. 2^64-1")
      ->capture_default_str()
      ->check(CLI::Validator(
          [&seed](std::string& v) {
            const char* end = v.data() + v.size();
            const auto [at, ec] = std::from_chars(v.data(), end, seed);
            return v.empty() || ec != std::errc() || at != end
                       ? "expected an integer from 0 to 2^64-1, got '" + sg::echoText(v) + "'"
                       : std::string();
          },
          "SEED"));
  sg::refuseEmptyValues(app);  // as simgrass and simgrass-viewer: '' is refused by name
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "simgrass-atlas: %s (see 'simgrass-atlas --help')\n", e.what());
    return 2;
  }

  {
    std::error_code ec;
    std::filesystem::create_directories(outDir, ec);  // fails on a file of that name: said below
    if (ec || !std::filesystem::is_directory(outDir, ec)) {
      std::fprintf(stderr, "simgrass-atlas: %s: expected a folder that exists or can be created%s%s\n", outDir.c_str(),
                   ec ? ": " : "", ec ? ec.message().c_str() : "");
      return 2;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const sg::viewer::TuftAtlas atlas = sg::viewer::makeTuftAtlas(variants, seed);
  const auto atlasDone = std::chrono::steady_clock::now();
  const sg::viewer::Image ground = sg::viewer::makeGroundTexture(atlas, seed);
  const auto groundDone = std::chrono::steady_clock::now();
  auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };

  const struct {
    std::string name;
    const sg::viewer::Image* image;
  } outputs[] = {{"tuft-atlas.png", &atlas.image}, {"ground-texture.png", &ground}};
  for (const auto& out : outputs) {
    const std::string path = (std::filesystem::path(outDir) / out.name).string();
    std::string error;
    if (!sg::viewer::writePng(path, *out.image, &error)) {
      std::fprintf(stderr, "simgrass-atlas: %s\n", error.c_str());
      return 1;
    }
    std::printf("wrote %s (%d x %d)\n", path.c_str(), out.image->width, out.image->height);
  }
  std::printf("atlas %.1f ms, ground %.1f ms (variants %d, seed %llu)\n", ms(start, atlasDone),
              ms(atlasDone, groundDone), variants, static_cast<unsigned long long>(seed));
  return 0;
}
