#include "sim/synthetic/scene.h"

namespace px::sim {

int Scene::FindMaterial(const std::string& material_name) const {
  for (size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == material_name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace px::sim
