//! The stable C ABI (`mi_*`): opaque handles, fixed result codes, a panic
//! boundary on every entry point. The only module besides [`crate::fmi`] with
//! unsafe code.
