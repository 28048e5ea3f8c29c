//! Which items one task of a job array runs: every K-th item of the manifest starting at I, so
//! the assignment is stable (it depends only on the manifest's order) and shards are disjoint.

use anyhow::{Context, bail};

/// Shard `index` of `count` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This task's index, `0..count`.
    pub index: usize,
    /// How many shards split the manifest.
    pub count: usize,
}

impl Shard {
    /// The whole manifest.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Whether the item at `position` (0-based, manifest order) belongs to this shard.
    pub fn contains(&self, position: usize) -> bool {
        position % self.count == self.index
    }

    /// Parses `I/K` with `0 <= I < K`.
    pub fn parse(text: &str) -> anyhow::Result<Shard> {
        let (i, k) = text
            .split_once('/')
            .with_context(|| format!("--shard {text:?} is not I/K"))?;
        let parse = |s: &str| {
            s.trim()
                .parse::<usize>()
                .map_err(|_| anyhow::anyhow!("--shard {text:?} is not I/K"))
        };
        let shard = Shard {
            index: parse(i)?,
            count: parse(k)?,
        };
        if shard.count == 0 || shard.index >= shard.count {
            bail!("--shard {text:?} needs 0 <= I < K");
        }
        Ok(shard)
    }

    /// The shard of a SLURM array task, from `SLURM_ARRAY_TASK_ID`, `_COUNT`, `_MIN` and
    /// `_STEP` as read by `var`; `None` outside an array job. The array must be a range
    /// (`--array=A-B` or `A-B:S`), so task ids map onto `0..count` one to one.
    pub fn from_slurm(var: impl Fn(&str) -> Option<String>) -> anyhow::Result<Option<Shard>> {
        let Some(id) = var("SLURM_ARRAY_TASK_ID") else {
            return Ok(None);
        };
        let number = |name: &str, default: Option<usize>| -> anyhow::Result<usize> {
            match var(name) {
                Some(v) => v
                    .trim()
                    .parse()
                    .map_err(|_| anyhow::anyhow!("{name}={v:?} is not a number")),
                None => {
                    default.with_context(|| format!("SLURM_ARRAY_TASK_ID is set but {name} is not"))
                }
            }
        };
        let id: usize = id
            .trim()
            .parse()
            .map_err(|_| anyhow::anyhow!("SLURM_ARRAY_TASK_ID={id:?} is not a number"))?;
        let count = number("SLURM_ARRAY_TASK_COUNT", None)?;
        let min = number("SLURM_ARRAY_TASK_MIN", Some(0))?;
        let step = number("SLURM_ARRAY_TASK_STEP", Some(1))?.max(1);
        if id < min || !(id - min).is_multiple_of(step) || (id - min) / step >= count || count == 0
        {
            bail!(
                "SLURM array task {id} is not in a range of {count} tasks from {min} by {step} \
                 (use --array=A-B or A-B:S, or pass --shard I/K)"
            );
        }
        Ok(Some(Shard {
            index: (id - min) / step,
            count,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| {
            pairs
                .iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn shards_partition_the_manifest() {
        let shards: Vec<Shard> = (0..4).map(|i| Shard { index: i, count: 4 }).collect();
        for position in 0..41 {
            let owners = shards.iter().filter(|s| s.contains(position)).count();
            assert_eq!(owners, 1);
        }
        assert!(shards[1].contains(5) && !shards[1].contains(6));
    }

    #[test]
    fn parse_checks_the_range() {
        assert_eq!(Shard::parse("2/5").unwrap(), Shard { index: 2, count: 5 });
        for bad in ["5/5", "1/0", "x/2", "3", "-1/2"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn slurm_ranges_map_to_shards() {
        assert_eq!(Shard::from_slurm(env(&[])).unwrap(), None);
        let plain = [
            ("SLURM_ARRAY_TASK_ID", "7"),
            ("SLURM_ARRAY_TASK_COUNT", "100"),
        ];
        assert_eq!(
            Shard::from_slurm(env(&plain)).unwrap(),
            Some(Shard {
                index: 7,
                count: 100
            })
        );
        let stepped = [
            ("SLURM_ARRAY_TASK_ID", "14"),
            ("SLURM_ARRAY_TASK_COUNT", "5"),
            ("SLURM_ARRAY_TASK_MIN", "10"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
        ];
        assert_eq!(
            Shard::from_slurm(env(&stepped)).unwrap(),
            Some(Shard { index: 2, count: 5 })
        );
        let outside = [
            ("SLURM_ARRAY_TASK_ID", "15"),
            ("SLURM_ARRAY_TASK_COUNT", "5"),
            ("SLURM_ARRAY_TASK_MIN", "10"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
        ];
        assert!(Shard::from_slurm(env(&outside)).is_err());
        assert!(Shard::from_slurm(env(&[("SLURM_ARRAY_TASK_ID", "1")])).is_err());
    }
}
