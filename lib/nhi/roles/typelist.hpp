// A compile-time list of types: the registries of systems (systems/registry.hpp)
// and of methods (methods.hpp) are TypeLists, and so are the typed-test lists
// the test suite derives from them (TypeList<...>::apply<::testing::Types>).
#pragma once

#include <type_traits>
#include <utility>

namespace nhi {

template <class... Ts>
struct TypeList {
  static constexpr int size = sizeof...(Ts);
  // TypeList<A, B>::apply<F> is F<A, B> (e.g. ::testing::Types<A, B>).
  template <template <class...> class F>
  using apply = F<Ts...>;
};

// f(std::type_identity-like tag) for each type, in order.
template <class T>
struct Tag {
  using type = T;
};

template <class... Ts, class F>
void for_each_type(TypeList<Ts...>, F&& f) {
  (f(Tag<Ts>{}), ...);
}

// The first type of a non-empty list.
template <class List>
struct Front;
template <class T, class... Ts>
struct Front<TypeList<T, Ts...>> {
  using type = T;
};

// The list without its first type.
template <class List>
struct Rest;
template <class T, class... Ts>
struct Rest<TypeList<T, Ts...>> {
  using type = TypeList<Ts...>;
};

// The I-th type of a list.
template <class List, int I>
struct At;
template <class T, class... Ts>
struct At<TypeList<T, Ts...>, 0> {
  using type = T;
};
template <class T, class... Ts, int I>
struct At<TypeList<T, Ts...>, I> {
  using type = typename At<TypeList<Ts...>, I - 1>::type;
};

// Concatenation and filtering by a trait Pred<T>::value.
template <class... Ls>
struct Concat;
template <>
struct Concat<> {
  using type = TypeList<>;
};
template <class... As>
struct Concat<TypeList<As...>> {
  using type = TypeList<As...>;
};
template <class... As, class... Bs, class... Rest>
struct Concat<TypeList<As...>, TypeList<Bs...>, Rest...> {
  using type = typename Concat<TypeList<As..., Bs...>, Rest...>::type;
};

// The types of List for which Pred<T>::value.  Pred is taken as a pack so that
// a trait with a defaulted SFINAE parameter (is_x<S, class = void>) matches.
template <template <class...> class Pred, class List>
struct Filter;
template <template <class...> class Pred, class... Ts>
struct Filter<Pred, TypeList<Ts...>> {
  using type = typename Concat<std::conditional_t<Pred<Ts>::value, TypeList<Ts>, TypeList<>>...>::type;
};
template <template <class...> class Pred, class List>
using filter_t = typename Filter<Pred, List>::type;

}  // namespace nhi
