//! The energy book of a run: the energy at the start, the internal energy
//! and what the run has booked as lost (to smoothing, contact, damping),
//! term by term in the order of the solver's balance. One struct for every
//! solver; its error is the balance's.

/// The energy at the start, the internal energy, and `N` losses in the
/// order that the balance adds them (each solver names its terms' places).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyBook<const N: usize> {
    /// The energy at the start: the impact's kinetic energy (J).
    pub initial: f64,
    /// The internal energy (J); zero in a solver that sums it from its
    /// cells when asked ([`EnergyBook::error_given`]).
    pub internal: f64,
    /// The energies booked as lost, in the order of the balance (J).
    pub lost: [f64; N],
}

impl<const N: usize> EnergyBook<N> {
    /// A book of `initial` with nothing yet internal or lost.
    pub fn new(initial: f64) -> Self {
        EnergyBook {
            initial,
            internal: 0.0,
            lost: [0.0; N],
        }
    }

    /// The relative error of the balance with the kinetic energy given,
    /// `|kinetic + internal + Σ lost − initial| / initial`, summed in that
    /// order.
    pub fn error(&self, kinetic: f64) -> f64 {
        self.error_given(kinetic, self.internal)
    }

    /// [`EnergyBook::error`] with the internal energy given.
    pub fn error_given(&self, kinetic: f64, internal: f64) -> f64 {
        let mut total = kinetic + internal;
        for lost in self.lost {
            total += lost;
        }
        (total - self.initial).abs() / self.initial
    }
}

/// The book as saved: `{initial, internal, lost: [...]}`.
#[derive(serde::Serialize)]
struct BookRef<'a> {
    initial: f64,
    internal: f64,
    lost: &'a [f64],
}

/// [`BookRef`] read back.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BookSaved {
    initial: f64,
    internal: f64,
    lost: Vec<f64>,
}

impl<const N: usize> serde::Serialize for EnergyBook<N> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        BookRef {
            initial: self.initial,
            internal: self.internal,
            lost: &self.lost,
        }
        .serialize(s)
    }
}

impl<'de, const N: usize> serde::Deserialize<'de> for EnergyBook<N> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error as _;
        let saved = BookSaved::deserialize(d)?;
        let n = saved.lost.len();
        let lost = saved
            .lost
            .try_into()
            .map_err(|_| D::Error::custom(format!("its energy book holds {n} losses, not {N}")))?;
        Ok(EnergyBook {
            initial: saved.initial,
            internal: saved.internal,
            lost,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The error is the balance's, summed in the book's order: the sum of
    /// the terms as written out by hand, bit for bit.
    #[test]
    fn the_error_is_the_balance_in_the_books_order() {
        let book = EnergyBook {
            initial: 10.0,
            internal: 3.0,
            lost: [0.1, 0.7, 1e-17],
        };
        let by_hand = ((((6.0 + 3.0) + 0.1) + 0.7) + 1e-17 - 10.0f64).abs() / 10.0;
        assert_eq!(book.error(6.0).to_bits(), by_hand.to_bits());
        assert_eq!(EnergyBook::<0>::new(4.0).error_given(3.0, 1.0), 0.0);
    }

    /// It saves as an object and reads back; a book with the wrong number
    /// of losses is refused, naming both counts.
    #[test]
    fn it_round_trips_and_refuses_the_wrong_count() {
        let book = EnergyBook {
            initial: 1.5,
            internal: 0.25,
            lost: [0.125, 0.0625],
        };
        let text = serde_json::to_string(&book).unwrap();
        assert_eq!(
            text,
            r#"{"initial":1.5,"internal":0.25,"lost":[0.125,0.0625]}"#
        );
        assert_eq!(serde_json::from_str::<EnergyBook<2>>(&text).unwrap(), book);
        let bytes = postcard::to_allocvec(&book).unwrap();
        assert_eq!(postcard::from_bytes::<EnergyBook<2>>(&bytes).unwrap(), book);
        let e = serde_json::from_str::<EnergyBook<3>>(&text).unwrap_err();
        assert!(e.to_string().contains("holds 2 losses, not 3"), "{e}");
    }
}
