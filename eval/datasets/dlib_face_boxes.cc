#include "eval/datasets/dlib_face_boxes.h"

#include <cstdlib>

#include "pipeline/io/durable_file.h"

namespace px::eval {
namespace {

// The value of attribute `name` in the tag text `tag` (quotes ' or "), or false when absent.
bool Attribute(const std::string& tag, const std::string& name, std::string* value) {
  size_t at = 0;
  while ((at = tag.find(name, at)) != std::string::npos) {
    const bool word_start = at > 0 && (tag[at - 1] == ' ' || tag[at - 1] == '\t' || tag[at - 1] == '\n');
    size_t eq = at + name.size();
    while (eq < tag.size() && tag[eq] == ' ') ++eq;
    if (!word_start || eq >= tag.size() || tag[eq] != '=') {
      at += name.size();
      continue;
    }
    size_t open = eq + 1;
    while (open < tag.size() && tag[open] == ' ') ++open;
    if (open >= tag.size() || (tag[open] != '\'' && tag[open] != '"')) return false;
    const size_t close = tag.find(tag[open], open + 1);
    if (close == std::string::npos) return false;
    *value = tag.substr(open + 1, close - open - 1);
    return true;
  }
  return false;
}

StatusOr<double> NumberAttribute(const std::string& tag, const std::string& name, const std::string& where) {
  std::string text;
  if (!Attribute(tag, name, &text)) return InvalidArgumentError(where + ": no attribute '" + name + "' in " + tag);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0') {
    return InvalidArgumentError(where + ": attribute " + name + "='" + text + "' is not a number");
  }
  return value;
}

}  // namespace

StatusOr<std::vector<LabelledFaceImage>> ParseDlibFaceBoxes(const std::string& xml) {
  std::vector<LabelledFaceImage> images;
  size_t at = 0;
  while ((at = xml.find('<', at)) != std::string::npos) {
    const size_t end = xml.find('>', at);
    if (end == std::string::npos)
      return InvalidArgumentError("dlib face XML: unterminated tag at byte " + std::to_string(at));
    const std::string tag = xml.substr(at, end - at + 1);
    at = end + 1;
    if (tag.rfind("<image", 0) == 0 && (tag.size() > 6 && (tag[6] == ' ' || tag[6] == '>'))) {
      LabelledFaceImage image;
      if (!Attribute(tag, "file", &image.file) || image.file.empty()) {
        return InvalidArgumentError("dlib face XML: <image> without a file attribute: " + tag);
      }
      std::string size;
      if (Attribute(tag, "width", &size)) image.width = std::atoi(size.c_str());
      if (Attribute(tag, "height", &size)) image.height = std::atoi(size.c_str());
      images.push_back(std::move(image));
    } else if (tag.rfind("<box", 0) == 0) {
      if (images.empty()) return InvalidArgumentError("dlib face XML: <box> outside an <image>: " + tag);
      const std::string where = "dlib face XML, image " + images.back().file;
      PX_ASSIGN_OR_RETURN(const double top, NumberAttribute(tag, "top", where));
      PX_ASSIGN_OR_RETURN(const double left, NumberAttribute(tag, "left", where));
      PX_ASSIGN_OR_RETURN(const double width, NumberAttribute(tag, "width", where));
      PX_ASSIGN_OR_RETURN(const double height, NumberAttribute(tag, "height", where));
      if (!(width > 0 && height > 0)) {
        return InvalidArgumentError(where + ": box " + tag + " has width " + std::to_string(width) + " x height " +
                                    std::to_string(height) + " (must be > 0)");
      }
      std::string ignore;
      const bool ignored = Attribute(tag, "ignore", &ignore) && ignore != "0";
      (ignored ? images.back().ignored : images.back().faces).emplace_back(left, top, width, height);
    }
  }
  return images;
}

StatusOr<std::vector<LabelledFaceImage>> LoadDlibFaceBoxes(const std::filesystem::path& xml_path) {
  PX_ASSIGN_OR_RETURN(const std::string text, ReadFileToString(xml_path));
  StatusOr<std::vector<LabelledFaceImage>> images = ParseDlibFaceBoxes(text);
  if (!images.ok()) return InvalidArgumentError(xml_path.string() + ": " + std::string(images.status().message()));
  if (images->empty()) return InvalidArgumentError("dlib face XML " + xml_path.string() + ": holds no <image>");
  return images;
}

}  // namespace px::eval
