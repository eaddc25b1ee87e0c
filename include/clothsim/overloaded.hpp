// Overloaded: one visitor for std::visit from several lambdas, one per alternative (the overload pattern
// of cppreference's std::visit page).
#pragma once

namespace clothsim {

template <class... Ts>
struct Overloaded : Ts... {
    using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;  // C++20 deduces this itself; clang before 17 needs it spelled out

}  // namespace clothsim
