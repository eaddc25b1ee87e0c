#include "clothsim/spring.hpp"

namespace clothsim {

const char* to_string(SpringKind kind) {
    switch (kind) {
        case SpringKind::Structural: return "structural";
        case SpringKind::Shear: return "shear";
        case SpringKind::Bending: return "bending";
    }
    return "unknown";
}

}  // namespace clothsim
