//! What describes one tunable: its path in the settings' serde form, the pass it tunes, its
//! unit, its kind and range, and a line of help.

/// What kind of value a field holds, with its range.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    Bool,
    /// Integer in [min, max].
    Int(i64, i64),
    /// Real in [min, max], dragged by `speed` per pixel.
    Float(f64, f64, f64),
    /// One of the names `choices()` lists (the serde names of an enum).
    Choice(fn() -> Vec<String>),
}

#[derive(Clone, Copy, Debug)]
pub struct Field {
    /// Dotted path in the serde form, e.g. `matte.hysteresis`.
    pub path: &'static str,
    /// The pass (or part of the frame) it tunes, as the passes are named in timings.
    pub group: &'static str,
    pub unit: &'static str,
    pub kind: Kind,
    pub help: &'static str,
}

pub(super) fn names<T: serde::Serialize>(all: &[T]) -> Vec<String> {
    all.iter()
        .map(|v| {
            serde_json::to_value(v)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_default()
        })
        .collect()
}

pub(super) const fn f(
    path: &'static str,
    group: &'static str,
    unit: &'static str,
    kind: Kind,
    help: &'static str,
) -> Field {
    Field { path, group, unit, kind, help }
}

/// Declares a technique's settings struct, its `Default` and its [`Field`] table from one text
/// per setting: a field's doc comment is also its help in the viewer and in errors. Fields under
/// `hidden` have no [`Field`] (they are not settings a user sets: test hooks).
macro_rules! described {
    (
        $(#[$meta:meta])*
        pub struct $name:ident / $table:ident {
            $(
                $(#[doc = $doc:literal])+
                $field:ident: $ty:ty = $default:expr,
                    ($path:literal, $group:literal, $unit:literal, $kind:expr);
            )*
        }
        hidden {
            $( $(#[$hmeta:meta])* $hfield:ident: $hty:ty = $hdefault:expr; )*
        }
    ) => {
        $(#[$meta])*
        pub struct $name {
            $( $(#[doc = $doc])+ pub $field: $ty, )*
            $( $(#[$hmeta])* pub $hfield: $hty, )*
        }

        impl Default for $name {
            fn default() -> Self {
                $name { $( $field: $default, )* $( $hfield: $hdefault, )* }
            }
        }

        /// Its fields, in panel order; each one's help is its doc comment.
        pub const $table: &[$crate::settings::Field] = &[
            $( $crate::settings::field::f($path, $group, $unit, $kind, concat!($($doc),+)), )*
        ];
    };
}
pub(super) use described;
