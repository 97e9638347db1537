#pragma once
// MetaIO's AnatomicalOrientation letters, read (to note a disagreement with
// TransformMatrix) and written by the MetaImage reader and writer.
#include <string>

#include <glm/mat3x3.hpp>

#include "tessera/core/PatientFrame.h"

namespace tessera::io_detail {

// MetaIO's AnatomicalOrientation letters name the side each index axis
// comes *from* (MET_OrientationTypeName "RL" -> 'R'; ITK writes RightToLeft
// as 'R'), the opposite of nibabel's axis codes: identity LPS is "RAI".
inline char fromLetter(char toLetter) {
  switch (toLetter) {
    case 'R':
      return 'L';
    case 'L':
      return 'R';
    case 'A':
      return 'P';
    case 'P':
      return 'A';
    case 'S':
      return 'I';
    case 'I':
      return 'S';
    default:
      return '?';
  }
}

inline std::string metaOrientation(const glm::dmat3& rasDirection) {
  std::string code = orientationOf(rasDirection).code;
  for (char& c : code) c = fromLetter(c);
  return code;
}

}  // namespace tessera::io_detail
