//! Every parameter of simplification, reconstruction and normal estimation in one table: its
//! name (the C field and the Python keyword), command-line flag, label, default, range, unit,
//! description and, for a choice, each value's number, name and description.
//!
//! The library's `Default`s and range checks read it, the command line takes its flags'
//! defaults and help from it, and the C API hands it out (`vstree_param_count()`,
//! `vstree_param_get()`, `vstree_param_choice_get()`), from which the Python binding, the
//! MeshLab plugin and the Blender add-on build their keywords, dialogs and properties. A test
//! per surface fails where a surface says otherwise.

use crate::error::{Error, Result};

mod table;
pub use table::*;

/// The call a parameter belongs to (its C struct).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Call {
    /// `vstree_simplify_params` (also the tree's and the cluster labels').
    Simplify = 0,
    /// `vstree_reconstruct_params`.
    Reconstruct = 1,
    /// `vstree_normal_params`.
    Normals = 2,
}

/// What values a parameter takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A real number within the range.
    Real = 0,
    /// A whole number within the range.
    Integer = 1,
    /// 0 (off) or 1 (on).
    Flag = 2,
    /// One of the [`Param::choices`], by number.
    Choice = 3,
}

/// One value of a choice. Its label is also its name in the MeshLab plugin's dialog and in
/// pymeshlab scripts: changing one breaks those scripts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Choice {
    /// The number the C field holds.
    pub value: i32,
    /// The name the command line and the bindings take (lower case, `_` between words).
    pub name: &'static str,
    /// A short label for a dialog.
    pub label: &'static str,
    /// What it does.
    pub help: &'static str,
}

/// One parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Param {
    pub call: Call,
    /// The C field's name, which Python's keyword and the hosts' properties share.
    pub name: &'static str,
    /// The command line's long flag (without `--`), where one sets this field alone.
    pub flag: Option<&'static str>,
    /// A short label for a dialog.
    pub label: &'static str,
    pub kind: Kind,
    /// The default value (a choice's number, a flag's 0 or 1).
    pub default: f64,
    /// The range: `min` to `max`, each end included unless `*_open`. Infinite where unbounded.
    pub min: f64,
    pub max: f64,
    pub min_open: bool,
    pub max_open: bool,
    /// What a value counts in ("" for a choice or a plain number).
    pub unit: &'static str,
    /// What it does, for a tooltip or `--help`.
    pub help: &'static str,
    /// A choice's values, in their numbers' order.
    pub choices: &'static [Choice],
}

impl Param {
    const fn new(call: Call, name: &'static str, label: &'static str, kind: Kind, help: &'static str) -> Param {
        Param {
            call,
            name,
            flag: None,
            label,
            kind,
            default: 0.0,
            min: 0.0,
            max: f64::INFINITY,
            min_open: false,
            max_open: false,
            unit: "",
            help,
            choices: &[],
        }
    }

    const fn flag(self, flag: &'static str) -> Param {
        Param { flag: Some(flag), ..self }
    }

    const fn default(self, default: f64) -> Param {
        Param { default, ..self }
    }

    /// The closed range `[min, max]`.
    const fn range(self, min: f64, max: f64) -> Param {
        Param { min, max, ..self }
    }

    const fn open(self, min_open: bool, max_open: bool) -> Param {
        Param { min_open, max_open, ..self }
    }

    const fn unit(self, unit: &'static str) -> Param {
        Param { unit, ..self }
    }

    const fn choices(self, choices: &'static [Choice], default: i32) -> Param {
        let last = choices.len() as f64 - 1.0;
        Param { choices, default: default as f64, min: 0.0, max: last, ..self }
    }

    /// Whether `value` lies in the range (a choice: is one of the choices' numbers).
    pub fn allows(&self, value: f64) -> bool {
        if self.kind == Kind::Choice {
            return self.choices.iter().any(|c| f64::from(c.value) == value);
        }
        let above = if self.min_open { value > self.min } else { value >= self.min };
        let below = if self.max_open { value < self.max } else { value <= self.max };
        let whole = !matches!(self.kind, Kind::Integer | Kind::Flag) || value.fract() == 0.0;
        value.is_finite() && above && below && whole
    }

    /// The range in words, as the error messages say it: "in [0, 1]", "from 1 to 30", "a finite
    /// number > 0".
    pub fn range_text(&self) -> String {
        match self.kind {
            Kind::Choice => {
                let names: Vec<String> = self.choices.iter().map(|c| format!("{} ({})", c.value, c.name)).collect();
                format!("one of {}", names.join(", "))
            }
            Kind::Flag => "0 or 1".to_string(),
            Kind::Integer => format!("from {} to {}", self.min, self.max),
            Kind::Real if self.max == f64::INFINITY => {
                format!("a finite number {} {}", if self.min_open { ">" } else { ">=" }, self.min)
            }
            Kind::Real => format!(
                "in {}{}, {}{}",
                if self.min_open { "(" } else { "[" },
                self.min,
                self.max,
                if self.max_open { ")" } else { "]" }
            ),
        }
    }

    /// `value` if the range allows it, else the error naming the parameter; `shown` is the
    /// value as the caller gave it (an `f32` prints shorter than its `f64`).
    pub fn check(&self, value: f64, shown: impl std::fmt::Display) -> Result<()> {
        if self.allows(value) {
            return Ok(());
        }
        Err(Error::param(self.name, format!("{shown}: must be {}", self.range_text())))
    }

    /// The default as the field's type holds it.
    pub const fn default_u32(&self) -> u32 {
        self.default as u32
    }
}

/// The parameter `name` of `call`.
pub fn find(call: Call, name: &str) -> Option<&'static Param> {
    PARAMS.iter().find(|p| p.call == call && p.name == name)
}
