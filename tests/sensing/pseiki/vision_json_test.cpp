// The JSON forms of `spar vision` (sensing/pseiki/vision_json.hpp): image files read with each
// mistake named by its place, and the normative keys of render and match, with ids echoed as
// written.
#include "spar/sensing/pseiki/vision_json.hpp"

#include <gtest/gtest.h>

#include "tests/common/expect_message.hpp"
#include "tests/sensing/pseiki/scenes.hpp"

namespace spar::sensing::pseiki {
namespace {

TEST(ImageFile, ReadsIdsAsWrittenAndIgnoresOtherKeys) {
  const ImageFile image = parse_image_json(
      R"({"camera": "front", "edges": [{"id": "a", "p0": [1, 2], "p1": [3, 4], "truth": null},
                                       {"id": 7, "p0": [0, 0], "p1": [0, 9.5], "object": "x"}]})",
      "image.json");
  ASSERT_EQ(image.edges.size(), 2U);
  EXPECT_EQ(image.edges[0].id, "a");
  EXPECT_EQ(image.edges[1].id, "7");
  EXPECT_TRUE(image.ids[1].is_number_integer());
  EXPECT_EQ(image.edges[1].segment.p1, Eigen::Vector2d(0, 9.5));
}

TEST(ImageFile, MistakesNameTheirPlace) {
  const auto error = [](const std::string& text) {
    try {
      (void)parse_image_json(text, "image.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("{\"edges\": [}").find("image.json:1:12: JSON syntax error"), std::string::npos);
  EXPECT_EQ(error("[]"),
            "image.json: expected an object {\"edges\": [{\"id\", \"p0\", \"p1\"}, ...]}");
  EXPECT_EQ(error(R"({"edges": [{"id": "a", "p0": [1, 2]}]})"),
            "image.json: edges[0]: missing key 'p1'");
  EXPECT_EQ(error(R"({"edges": [{"id": "a", "p0": [1], "p1": [1, 2]}]})"),
            "image.json: edges[0].p0: expected [u, v] (two numbers, pixels), got [1]");
  EXPECT_EQ(error(R"({"edges": [{"id": 1.5, "p0": [0, 0], "p1": [1, 2]}]})"),
            "image.json: edges[0].id: expected a name or a whole number, got 1.5");
  EXPECT_EQ(error(R"({"edges": [{"id": "a", "p0": [0, 0], "p1": [1, 2]},
                               {"id": "a", "p0": [0, 0], "p1": [1, 3]}]})"),
            "image.json: edges[1].id: 'a' is used twice");
  EXPECT_EQ(error(R"({"edges": [{"id": "a", "p0": [1, 2], "p1": [1, 2]}]})"),
            "image.json: edges[0]: p0 and p1 are the same point, not an edge");
  EXPECT_THROW_MESSAGE(load_image_file("/nonexistent/image.json"),
                       "/nonexistent/image.json: cannot read the image file: no such file");
}

TEST(VisionJson, RenderAndMatchHaveTheNormativeKeys) {
  const testing::TestScene test = testing::two_boxes();
  const ModelPanel panel(test.scene, test.camera, test.uncertainty);
  const auto rendered = render_json(panel, "front");
  EXPECT_EQ(rendered["camera"], "front");
  ASSERT_EQ(rendered["edges"].size(), panel.edges().size());
  for (const char* key : {"id", "object", "faces", "p0", "p1"})
    EXPECT_TRUE(rendered["edges"][0].contains(key)) << key;
  for (const char* key : {"id", "object", "edges"})
    EXPECT_TRUE(rendered["faces"][0].contains(key)) << key;
  EXPECT_EQ(rendered["objects"].size(), 2U);

  // The rendered edges as an image, with whole-number ids.
  std::string text = "{\"edges\": [";
  for (std::size_t e = 0; e < rendered["edges"].size(); ++e)
    text += (e ? ", " : "") + std::string("{\"id\": ") + std::to_string(100 + e) +
            ", \"p0\": " + rendered["edges"][e]["p0"].dump() +
            ", \"p1\": " + rendered["edges"][e]["p1"].dump() + "}";
  const ImageFile image = parse_image_json(text + "]}", "rendered");
  MatchOptions options;
  const Verification result =
      verify(test.scene, test.camera, test.uncertainty, image.edges, options);
  const auto matched = match_json(result, image, "front", {}, options.acceptance);
  for (const char* key : {"edges", "faces", "objects", "scene", "pose_correction"})
    EXPECT_TRUE(matched.contains(key)) << key;
  ASSERT_EQ(matched["edges"].size(), panel.edges().size());
  for (std::size_t e = 0; e < panel.edges().size(); ++e) {
    EXPECT_EQ(matched["edges"][e]["id"], 100 + static_cast<int>(e));
    EXPECT_EQ(matched["edges"][e]["label"], panel.edges()[e].id);
    EXPECT_GT(matched["edges"][e]["belief"].get<double>(), 0.5);
  }
  EXPECT_TRUE(matched["scene"]["accepted"].get<bool>());
  EXPECT_TRUE(matched["faces"][0].contains("members"));
  const auto& correction = matched["pose_correction"];
  ASSERT_TRUE(correction.is_object());
  for (const char* key : {"object", "xyz", "rpy", "residual"})
    EXPECT_TRUE(correction.contains(key)) << key;
  EXPECT_LT(correction["residual"].get<double>(), 0.5);
}

}  // namespace
}  // namespace spar::sensing::pseiki
