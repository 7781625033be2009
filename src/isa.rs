//! The instruction sets the hot loops are compiled for, and the choice among
//! them.
//!
//! Each hot function is written once (the crate's `hot!` macro) and
//! compiled three times: for AVX-512 (F and VL), for AVX2 with FMA, and for
//! baseline x86-64 (or the target's baseline elsewhere). A run uses the best
//! copy its processor has ([`Isa::best`]) unless told otherwise
//! ([`crate::Simulation::set_isa`]). Every copy performs the same IEEE
//! operations in the same order, so they give the same bits; the golden test
//! (`tests/suite/golden.rs`) runs each one this processor has.
//!
//! An [`Isa`] can only be obtained for a copy this processor runs, which is
//! what makes calling the AVX copies sound.

/// Level of the baseline copy (the `ISA` const parameter of a hot body).
pub(crate) const BASELINE: u8 = 0;
/// Level of the AVX2+FMA copy.
pub(crate) const AVX2_FMA: u8 = 1;
/// Level of the AVX-512 copy.
pub(crate) const AVX512: u8 = 2;

/// A compiled copy of the hot loops that this processor runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Isa(u8);

impl Default for Isa {
    /// The best copy this processor runs.
    fn default() -> Self {
        Isa::best()
    }
}

impl Isa {
    /// The baseline copy, which every processor runs.
    pub const BASELINE: Isa = Isa(BASELINE);

    /// Every copy, best first, with its name.
    const ALL: [(u8, &'static str); 3] = [
        (AVX512, "avx512"),
        (AVX2_FMA, "avx2+fma"),
        (BASELINE, "baseline"),
    ];

    /// Whether this processor runs the copy of this level.
    fn runs(level: u8) -> bool {
        match level {
            #[cfg(target_arch = "x86_64")]
            AVX512 => {
                std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512vl")
            }
            #[cfg(target_arch = "x86_64")]
            AVX2_FMA => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            BASELINE => true,
            _ => false,
        }
    }

    /// The copies this processor runs, best first.
    pub fn available() -> Vec<Isa> {
        Self::ALL
            .iter()
            .filter(|(level, _)| Self::runs(*level))
            .map(|&(level, _)| Isa(level))
            .collect()
    }

    /// The best copy this processor runs.
    pub fn best() -> Isa {
        // Without the vector of `available`: `Neighbourhood::power_sums`
        // asks for it on every call.
        Self::ALL
            .iter()
            .find(|(level, _)| Self::runs(*level))
            .map_or(Isa::BASELINE, |&(level, _)| Isa(level))
    }

    /// The copy called `name` (`avx512`, `avx2+fma` or `baseline`), if this
    /// processor runs it; otherwise a message naming what it runs.
    pub fn named(name: &str) -> std::result::Result<Isa, String> {
        let names = |v: &mut dyn Iterator<Item = &'static str>| v.collect::<Vec<_>>().join(", ");
        let Some(&(level, _)) = Self::ALL.iter().find(|(_, n)| *n == name) else {
            return Err(format!(
                "unknown instruction set `{name}`; allowed: {}",
                names(&mut Self::ALL.iter().map(|(_, n)| *n))
            ));
        };
        if !Self::runs(level) {
            return Err(format!(
                "this processor does not run the `{name}` copy; it runs: {}",
                names(&mut Self::available().into_iter().map(Isa::name))
            ));
        }
        Ok(Isa(level))
    }

    /// The copy's name, as [`Isa::named`] takes it.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(level, _)| *level == self.0)
            .map_or("baseline", |(_, n)| *n)
    }

    /// The copy's level ([`BASELINE`], [`AVX2_FMA`] or [`AVX512`]).
    pub(crate) fn level(self) -> u8 {
        self.0
    }
}

/// Defines a hot function once and compiles it for each [`Isa`]: the
/// function gains a first argument `isa: Isa` and calls the copy of that
/// level. Inside the body, the const `ISA` is the level of the copy being
/// compiled (for [`on_avx512!`]).
///
/// The body is `#[inline(always)]` into functions with
/// `#[target_feature]`, so it is compiled with their instruction sets (the
/// functions it calls are compiled for the baseline unless they are inlined
/// too).
macro_rules! hot {
    (
        $(#[$meta:meta])*
        $vis:vis fn $name:ident $(<const $k:ident: $kt:ty>)?
        ($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)?
        $body:block
    ) => {
        $(#[$meta])*
        #[allow(unsafe_code)]
        $vis fn $name $(<const $k: $kt>)? (
            isa: $crate::isa::Isa,
            $($arg: $ty),*
        ) $(-> $ret)? {
            #[inline(always)]
            fn body<const ISA: u8 $(, const $k: $kt)?>($($arg: $ty),*) $(-> $ret)? $body

            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx512f,avx512vl")]
            fn avx512 $(<const $k: $kt>)? ($($arg: $ty),*) $(-> $ret)? {
                body::<{ $crate::isa::AVX512 } $(, $k)?>($($arg),*)
            }

            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2,fma")]
            fn avx2_fma $(<const $k: $kt>)? ($($arg: $ty),*) $(-> $ret)? {
                body::<{ $crate::isa::AVX2_FMA } $(, $k)?>($($arg),*)
            }

            match isa.level() {
                // SAFETY: an `Isa` of this level exists only where the
                // processor has AVX-512 F and VL (`Isa::runs`).
                #[cfg(target_arch = "x86_64")]
                $crate::isa::AVX512 => unsafe { avx512 $(::<$k>)? ($($arg),*) },
                // SAFETY: likewise, AVX2 and FMA.
                #[cfg(target_arch = "x86_64")]
                $crate::isa::AVX2_FMA => unsafe { avx2_fma $(::<$k>)? ($($arg),*) },
                _ => body::<{ $crate::isa::BASELINE } $(, $k)?>($($arg),*),
            }
        }
    };
}
pub(crate) use hot;

/// `on_avx512!(ISA, fast, plain)`: in a [`hot!`] body,
/// `fast` (a call of an AVX-512 function) in the AVX-512 copy and `plain`
/// elsewhere.
macro_rules! on_avx512 {
    ($isa:expr, $fast:expr, $plain:expr) => {{
        #[cfg(target_arch = "x86_64")]
        let value = if $isa == $crate::isa::AVX512 {
            // SAFETY: this is the AVX-512 copy of a `hot!` function, which
            // runs only where the processor has AVX-512 F and VL.
            #[allow(unsafe_code)]
            let value = unsafe { $fast };
            value
        } else {
            $plain
        };
        #[cfg(not(target_arch = "x86_64"))]
        let value = $plain;
        value
    }};
}
pub(crate) use on_avx512;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_refuse_what_the_processor_lacks() {
        for isa in Isa::available() {
            assert_eq!(Isa::named(isa.name()), Ok(isa));
        }
        assert_eq!(Isa::named("baseline"), Ok(Isa::BASELINE));
        assert_eq!(*Isa::available().last().unwrap(), Isa::BASELINE);
        let e = Isa::named("sse9").unwrap_err();
        assert!(
            e.contains("`sse9`") && e.contains("avx512, avx2+fma, baseline"),
            "{e}"
        );
        for (level, name) in Isa::ALL {
            assert_eq!(Isa::named(name).is_ok(), Isa::runs(level), "{name}");
        }
    }
}
