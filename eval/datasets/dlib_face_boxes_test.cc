// dlib's imglab XML: parsed from text (always), and the real faces_dlib_pascalvoc file when present.
#include "eval/datasets/dlib_face_boxes.h"

#include <gtest/gtest.h>

#include "sim/synthetic/data_paths.h"

namespace px::eval {
namespace {

TEST(DlibFaceBoxesTest, ParsesImagesBoxesAndIgnoredBoxes) {
  const std::string xml =
      "<?xml version='1.0'?>\n<dataset><images>\n"
      "<image file='a.jpg' width='500' height='375'>\n"
      "  <box top='90' left='194' width='37' height='38'/>\n"
      "  <box top=\"10\" left=\"20\" width=\"30\" height=\"30\" ignore='1'/>\n"
      "</image>\n<image file='b.jpg'></image>\n</images></dataset>";
  auto images = ParseDlibFaceBoxes(xml);
  ASSERT_TRUE(images.ok()) << images.status().ToString();
  ASSERT_EQ(images->size(), 2u);
  EXPECT_EQ((*images)[0].file, "a.jpg");
  EXPECT_EQ((*images)[0].width, 500);
  ASSERT_EQ((*images)[0].faces.size(), 1u);
  EXPECT_EQ((*images)[0].faces[0], cv::Rect2d(194, 90, 37, 38));
  ASSERT_EQ((*images)[0].ignored.size(), 1u);
  EXPECT_TRUE((*images)[1].faces.empty());
}

TEST(DlibFaceBoxesTest, BadInputNamesTheImageAndAttribute) {
  auto no_width = ParseDlibFaceBoxes("<image file='a.jpg'><box top='1' left='2' height='3'/></image>");
  ASSERT_FALSE(no_width.ok());
  EXPECT_NE(no_width.status().message().find("a.jpg"), std::string::npos) << no_width.status().ToString();
  EXPECT_NE(no_width.status().message().find("width"), std::string::npos) << no_width.status().ToString();
  auto not_number = ParseDlibFaceBoxes("<image file='a.jpg'><box top='x' left='2' width='3' height='3'/></image>");
  ASSERT_FALSE(not_number.ok());
  EXPECT_NE(not_number.status().message().find("top='x'"), std::string::npos) << not_number.status().ToString();
  EXPECT_FALSE(ParseDlibFaceBoxes("<box top='1' left='2' width='3' height='3'/>").ok());
  EXPECT_FALSE(ParseDlibFaceBoxes("<image file='a.jpg'><box top='1' left='2' width='0' height='3'/>").ok());
  EXPECT_FALSE(LoadDlibFaceBoxes("/nonexistent/training.xml").ok());
}

TEST(DlibFaceBoxesTest, ReadsThePascalVocFaceSet) {
  const std::filesystem::path xml = sim::SharedDataDir() / "faces_dlib_pascalvoc" / "training.xml";
  if (!std::filesystem::exists(xml)) GTEST_SKIP() << "real data absent: " << xml.parent_path().string();
  auto images = LoadDlibFaceBoxes(xml);
  ASSERT_TRUE(images.ok()) << images.status().ToString();
  size_t faces = 0;
  for (const LabelledFaceImage& image : *images) faces += image.faces.size();
  EXPECT_EQ(images->size(), 4u);  // SOURCES.md 11: 4 photos, 18 labelled faces
  EXPECT_EQ(faces, 18u);
}

}  // namespace
}  // namespace px::eval
