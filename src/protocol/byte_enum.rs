//! One definition per byte-coded field of the link: each value's variant,
//! byte and name in one line, so the decoder, the encoder and the printed
//! names cannot disagree.

/// Defines a `#[repr(u8)]` enum with `from_byte`, `name` and `Display`.
macro_rules! byte_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $( $(#[$vmeta:meta])* $variant:ident = $value:literal => $text:literal, )+
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[repr(u8)]
        pub enum $name {
            $( $(#[$vmeta])* $variant = $value, )+
        }

        impl $name {
            /// The value of a byte, if this version of the protocol defines it.
            pub const fn from_byte(b: u8) -> Option<Self> {
                match b {
                    $( $value => Some(Self::$variant), )+
                    _ => None,
                }
            }

            /// Its name, as docs/PROTOCOL.md and `triad device` print it.
            pub const fn name(self) -> &'static str {
                match self {
                    $( Self::$variant => $text, )+
                }
            }
        }

        impl core::fmt::Display for $name {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}

pub(crate) use byte_enum;
