//! Tests of `super`: operations counted on small generated bodies.

use super::*;

fn count(body: &str) -> Option<OpCount> {
    let file: syn::File = syn::parse_str(&format!(
        "impl<T> S<T> {{ fn gauss(&self, q: Q, qd: Q, t: T, correction: C) -> R {{ {body} }} }}"
    ))
    .expect("test source parses");
    acceleration(&file)
}

#[test]
fn counts_only_what_the_acceleration_reads() {
    let ops = count(
        "let [[x, y]] = q.data.0;
         let __t0 = x * y + t.sin();
         let __unused = x / y / y;
         let (__r0,) = match correction {
             ::core::option::Option::Some(__db) => (__r0 + __db,),
             ::core::option::Option::None => (__t0,),
         };
         let __f = -__r0 * x;
         let __t0 = __t0 - __f;
         if !(__t0.is_finite()) {
             let __f = x / y / y;
             let __acc = V::from_array_storage(ArrayStorage([[__f, __f]]));
             if let Some(__r) = checked(self, q, qd, t, correction, __acc) {
                 return __F::settle(self, q, qd, t, correction, __r);
             }
             return __F::stands(__acc, move || x);
         }
         __F::stands(
             V::from_array_storage(ArrayStorage([[__t0, __f * __f]])),
             move || x * x * x,
         )",
    )
    .expect("straight-line");
    // x·y, + sin t, one sin; −, ·; the second __t0's −; __f·__f. Not
    // the suspect path's divisions, not the force's products.
    assert_eq!(
        ops,
        OpCount {
            add: 1,
            sub: 1,
            mul: 3,
            div: 0,
            neg: 1,
            functions: 1
        }
    );
    assert_eq!(ops.total(), 7);
    // The same body with its first lines in an exporting block
    // (`crate::emit::chunks`) counts the same.
    let grouped = count(
        "let (x, y, __t0,) = {
             let [[x, y]] = q.data.0;
             let __t0 = x * y + t.sin();
             let __unused = x / y / y;
             (x, y, __t0,)
         };
         let __f = -__t0 * x;
         __F::stands(
             V::from_array_storage(ArrayStorage([[__t0, __f * __f]])),
             move || x * x * x,
         )",
    )
    .expect("straight-line");
    assert_eq!(grouped.total(), 6);
}

#[test]
fn the_multipliers_add_what_they_alone_need() {
    let file: syn::File = syn::parse_str(
        "impl<T> S<T> { fn gauss(&self, q: Q, qd: Q, t: T, correction: C) -> R {
             let [[x, y]] = q.data.0;
             let __a = x * y;
             let __m = __a - y;
             let __n = __m / x;
             __F::stands_with(
                 V::from_array_storage(ArrayStorage([[__a, __m]])),
                 move || x * x,
                 move || ::core::option::Option::Some([-__m, __n + __a]),
             )
         } }",
    )
    .expect("test source parses");
    // q̈: x·y, −. λ adds its own /, −, + and shares __m, __a.
    assert_eq!(acceleration(&file).map(|o| o.total()), Some(2));
    let both = acceleration_and_multipliers(&file).expect("straight-line");
    assert_eq!((both.total(), both.div, both.neg), (5, 1, 1));
}

/// A method whose outputs are stored into a local as they become known
/// (`crate::emit::body`'s stores) counts every store the local's value
/// reads, and what each one needs, once.
#[test]
fn stores_into_the_returned_local_count() {
    let file: syn::File = syn::parse_str(
        "impl<T> S<T> { fn mass_matrix(&self, q: Q, t: T) -> R {
             let [[x, y]] = q.data.0;
             let mut __out0 = M::zeros();
             let __t0 = x * y;
             __out0.data.0[0][0] = __t0 + x;
             let __unused = x / y;
             __out0.data.0[1][0] = __t0;
             __out0.data.0[0][1] = __t0;
             __out0.data.0[1][1] = __t0 - y * y;
             __out0
         } }",
    )
    .expect("test source parses");
    // x·y, + x, y·y and its −: not the unused division.
    let ops = method(&file, "mass_matrix").expect("straight-line");
    assert_eq!((ops.total(), ops.div), (4, 0));
}

#[test]
fn a_runtime_solve_has_no_count() {
    assert_eq!(
        count(
            "let __motion = ::constrained::__private::gauss_dense(self, q, qd, t, correction);
             __F::settle(self, q, qd, t, correction, __motion)"
        ),
        None
    );
    assert_eq!(count("let m = self.m;"), None, "no returned acceleration");
}

/// A function the body defines (the legs' shared factor code) counts what
/// its value needs at each call whose result the acceleration reads, and a
/// call nothing reads counts nothing.
#[test]
fn a_nested_function_counts_at_every_call_that_is_read() {
    let ops = count(
        "let [[x, y]] = q.data.0;
         #[inline(never)]
         fn __leg_share<T: RealField + Copy>(__inputs: &[T; 2]) -> ::core::option::Option<[T; 2]> {
             let [__lit0]: [T; 1] = [::constrained::__private::lit::<T>(0.5f64)];
             let [__a, __b] = *__inputs;
             let __unused = __a / __b;
             if !(__b > __lit0) {
                 return ::core::option::Option::None;
             }
             let __p = __a * __b;
             ::core::option::Option::Some([__p + __lit0, __p])
         }
         let ::core::option::Option::Some(__o0) = __leg_share::<T>(&[x, y]) else {
             return __F::settle(self, q, qd, t, correction, x);
         };
         let [__s0, __p0] = __o0;
         let ::core::option::Option::Some(__o1) = __leg_share::<T>(&[x - y, y]) else {
             return __F::settle(self, q, qd, t, correction, x);
         };
         let [__s1, __p1] = __o1;
         let ::core::option::Option::Some(__o2) = __leg_share::<T>(&[x, x]) else {
             return __F::settle(self, q, qd, t, correction, x);
         };
         let [__s2, __p2] = __o2;
         __F::stands(
             V::from_array_storage(ArrayStorage([[__s0, __p1 * __s1]])),
             move || x,
         )",
    )
    .expect("straight-line");
    // Two calls read, each one product and one sum (not the unread
    // division); `x − y`; the last product.
    assert_eq!(
        ops,
        OpCount {
            add: 2,
            sub: 1,
            mul: 3,
            div: 0,
            neg: 0,
            functions: 0
        }
    );
}
