//! The values of the `[arm]` table that a planar and a spatial arm spell differently: the arm's
//! kind and joint layout, the base pose, gravity (a magnitude or a vector) and the link inertias
//! (one number per link or a principal triple per link).

use lane_math::Compact;
use serde::de::{Error, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use sim_core::SimError;
use std::fmt;

/// The largest gravity a scenario takes, in magnitude or in any component of the vector
/// (m/s^2, about 100,000 g): beyond it the paper's arm under a bounded controller accelerates out
/// of double precision within a step, and the run would stop on a non-finite `a_ddot` instead of
/// naming `arm.gravity`.
pub const MAX_GRAVITY: f64 = 1e6;

/// Which modal arm a scenario runs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ArmKind {
    /// The paper's planar arm (eqs 1-18): `n` revolute joints in the `x-y` plane.
    #[default]
    Planar,
    /// A spatial modal arm (`docs/theory.md`, "Spatial modal arms"): `n` universal joints, two
    /// bending planes of `K` harmonics each, `m = 4K`.
    Spatial,
}

impl ArmKind {
    /// Whether this is the default, planar (the key is then left out of a written scenario).
    pub fn is_planar(&self) -> bool {
        *self == ArmKind::Planar
    }
}

/// The joints of a spatial arm.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum JointLayout {
    /// A universal joint per link: about the parent's `z` axis, then the resulting `y` axis,
    /// `theta = [z_1, y_1, z_2, y_2, ...]`.
    #[default]
    Universal,
}

/// The pose of a spatial arm's base: position and roll-pitch-yaw (URDF's convention), both
/// defaulting to zero (the straight arm along the world's `x` axis).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseSpec {
    /// Position of the first joint (m).
    #[serde(default, deserialize_with = "super::exact::numbers")]
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw (rad).
    #[serde(default, deserialize_with = "super::exact::numbers")]
    pub rpy: [f64; 3],
}

impl From<BaseSpec> for backbone_kin::BasePose {
    fn from(base: BaseSpec) -> Self {
        Self {
            xyz: base.xyz,
            rpy: base.rpy,
        }
    }
}

/// Gravity: a magnitude `g` (m/s^2) along the arm's down axis (`-y` for a planar arm, `-z` for
/// a spatial one), or a vector `[gx, gy, gz]` in the world frame (spatial arms only).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gravity {
    /// `g` along the down axis.
    Magnitude(f64),
    /// The vector (m/s^2).
    Vector([f64; 3]),
}

impl Gravity {
    /// The world-frame vector of a spatial arm: `[0, 0, -g]` for a magnitude (`+0` for `g = 0`,
    /// not `-0`).
    pub fn spatial(self) -> [f64; 3] {
        match self {
            Gravity::Magnitude(g) => [0.0, 0.0, 0.0 - g],
            Gravity::Vector(v) => v,
        }
    }

    /// Refuses a magnitude or a component that is not finite or beyond [`MAX_GRAVITY`], naming
    /// `arm.gravity` (or `arm.gravity[k]`).
    pub fn check(self) -> Result<(), SimError> {
        let bad = |name: String, value: f64| {
            SimError::setting(
                name,
                format!(
                    "must be finite and at most {} m/s^2 in magnitude, got {}",
                    Compact(MAX_GRAVITY),
                    Compact(value)
                ),
            )
        };
        let within = |x: f64| x.abs() <= MAX_GRAVITY;
        match self {
            Gravity::Magnitude(g) if !within(g) => Err(bad("arm.gravity".into(), g)),
            Gravity::Vector(v) => match v.iter().position(|&x| !within(x)) {
                Some(k) => Err(bad(format!("arm.gravity[{k}]"), v[k])),
                None => Ok(()),
            },
            Gravity::Magnitude(_) => Ok(()),
        }
    }
}

impl Serialize for Gravity {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Gravity::Magnitude(g) => serializer.serialize_f64(*g),
            Gravity::Vector(v) => v.serialize(serializer),
        }
    }
}

impl<'de> Deserialize<'de> for Gravity {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct GravityVisitor;
        impl<'de> Visitor<'de> for GravityVisitor {
            type Value = Gravity;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("gravity: a magnitude (m/s^2) or a vector [gx, gy, gz]")
            }
            fn visit_f64<E: Error>(self, v: f64) -> Result<Gravity, E> {
                Ok(Gravity::Magnitude(v))
            }
            fn visit_i64<E: Error>(self, v: i64) -> Result<Gravity, E> {
                Ok(Gravity::Magnitude(v as f64))
            }
            fn visit_u64<E: Error>(self, v: u64) -> Result<Gravity, E> {
                Ok(Gravity::Magnitude(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Gravity, A::Error> {
                triple(seq, "arm.gravity", "[gx, gy, gz]").map(Gravity::Vector)
            }
        }
        deserializer.deserialize_any(GravityVisitor)
    }
}

/// The links' inertias about their centres of mass: one number per link (kg m^2, a planar
/// arm's, about the joint axis) or a principal triple `[Ixx, Iyy, Izz]` per link in the link
/// frame (a spatial arm's, `x` along the link).
#[derive(Debug, Clone, PartialEq)]
pub enum Inertias {
    /// One inertia per link (planar arms).
    PerLink(Vec<f64>),
    /// `[Ixx, Iyy, Izz]` per link (spatial arms).
    Principal(Vec<[f64; 3]>),
}

impl Inertias {
    /// The number of links given.
    pub fn len(&self) -> usize {
        match self {
            Inertias::PerLink(values) => values.len(),
            Inertias::Principal(values) => values.len(),
        }
    }

    /// Whether no link is given.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl Serialize for Inertias {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Inertias::PerLink(values) => values.serialize(serializer),
            Inertias::Principal(values) => values.serialize(serializer),
        }
    }
}

/// One entry of an inertia list: a number or a triple.
enum InertiaEntry {
    One(f64),
    Triple([f64; 3]),
}

impl<'de> Deserialize<'de> for InertiaEntry {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct EntryVisitor;
        impl<'de> Visitor<'de> for EntryVisitor {
            type Value = InertiaEntry;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("an inertia (kg m^2) or a principal triple [Ixx, Iyy, Izz]")
            }
            fn visit_f64<E: Error>(self, v: f64) -> Result<InertiaEntry, E> {
                Ok(InertiaEntry::One(v))
            }
            fn visit_i64<E: Error>(self, v: i64) -> Result<InertiaEntry, E> {
                Ok(InertiaEntry::One(v as f64))
            }
            fn visit_u64<E: Error>(self, v: u64) -> Result<InertiaEntry, E> {
                Ok(InertiaEntry::One(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<InertiaEntry, A::Error> {
                triple(seq, "arm.inertias", "[Ixx, Iyy, Izz]").map(InertiaEntry::Triple)
            }
        }
        deserializer.deserialize_any(EntryVisitor)
    }
}

impl<'de> Deserialize<'de> for Inertias {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let entries = Vec::<InertiaEntry>::deserialize(deserializer)?;
        if entries.iter().all(|e| matches!(e, InertiaEntry::One(_))) {
            return Ok(Inertias::PerLink(
                entries
                    .iter()
                    .map(|e| match e {
                        InertiaEntry::One(v) => *v,
                        InertiaEntry::Triple(_) => unreachable!("all entries are numbers"),
                    })
                    .collect(),
            ));
        }
        entries
            .iter()
            .enumerate()
            .map(|(i, e)| match e {
                InertiaEntry::Triple(t) => Ok(*t),
                InertiaEntry::One(_) => Err(D::Error::custom(format!(
                    "arm.inertias[{i}] is a number but other entries are triples: give one \
                     number per link (planar arm) or one [Ixx, Iyy, Izz] per link (spatial arm)"
                ))),
            })
            .collect::<Result<_, _>>()
            .map(Inertias::Principal)
    }
}

/// Exactly three numbers from `seq`, the error naming `name` and the `shape` expected.
fn triple<'de, A: SeqAccess<'de>>(
    mut seq: A,
    name: &str,
    shape: &str,
) -> Result<[f64; 3], A::Error> {
    let mut values = [0.0; 3];
    for (k, value) in values.iter_mut().enumerate() {
        *value = seq.next_element()?.ok_or_else(|| {
            A::Error::custom(format!("{name} must have 3 entries {shape}, got {k}"))
        })?;
    }
    if seq.next_element::<f64>()?.is_some() {
        return Err(A::Error::custom(format!(
            "{name} must have 3 entries {shape}, got more"
        )));
    }
    Ok(values)
}
