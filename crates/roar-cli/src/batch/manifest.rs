//! The list of a batch's items: one input path a line, or a CSV/TSV table with a header naming
//! an `id` and a `path` column, optional per-item overrides and any other columns as labels.
//!
//! Blank lines and lines starting with `#` are ignored. Relative paths are relative to the
//! manifest's folder. A table's header must name `path`; it may also name `id`, `faces` (one
//! budget or several separated by `;` or spaces), `iterations`, `seed` and `timeout` (seconds).
//! Every other column is a label: its non-empty fields are kept as the item's labels, which the
//! batch records and `roar batch-report --by NAME` groups by. Column names are lowercased.
//! Fields are trimmed and may be wrapped in double quotes, but cannot contain the delimiter
//! (use TSV for paths with commas). Every error names the manifest's line.

use std::collections::{BTreeMap, HashMap};
use std::path::{Component, Path, PathBuf};

use anyhow::{Context, bail};

/// One input of a batch, with its per-item overrides.
#[derive(Debug, Clone, PartialEq)]
pub struct Item {
    /// Unique name of the item: its output folder under `OUTDIR`.
    pub id: String,
    /// The input file (or scan folder), resolved against the manifest's folder.
    pub input: PathBuf,
    /// Budgets of this item, replacing the batch's `--faces`.
    pub faces: Option<Vec<usize>>,
    /// Move Vertices iterations of this item.
    pub iterations: Option<usize>,
    /// Seed of this item.
    pub seed: Option<u64>,
    /// Timeout of this item in seconds, replacing the batch's `--timeout`.
    pub timeout: Option<f64>,
    /// The item's non-empty fields of the manifest's other columns, by column name.
    pub labels: BTreeMap<String, String>,
    /// 1-based line of the manifest the item comes from.
    pub line: usize,
}

/// Reads and parses a manifest file.
pub fn read_manifest(path: &Path) -> anyhow::Result<Vec<Item>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let base = path.parent().unwrap_or(Path::new(""));
    parse_manifest(&text, base).with_context(|| format!("manifest {}", path.display()))
}

/// Parses a manifest's text; relative paths are joined to `base`. Refuses an empty manifest,
/// an unnamed or repeated column, an unparsable override, an unsafe id and two items with one id.
pub fn parse_manifest(text: &str, base: &Path) -> anyhow::Result<Vec<Item>> {
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
        .collect();
    let Some(&(first_line, first)) = lines.first() else {
        bail!("no items");
    };
    let delimiter = if first.contains('\t') { '\t' } else { ',' };
    let header: Vec<String> = split(first, delimiter)
        .into_iter()
        .map(|f| f.to_ascii_lowercase())
        .collect();
    let items = if header.iter().any(|f| f == "path") {
        check_header(&header, first_line)?;
        parse_table(&header, &lines[1..], delimiter, base)?
    } else {
        lines
            .iter()
            .map(|&(line, path)| {
                let path = unquote(path);
                Ok(Item {
                    id: id_from_path(path),
                    input: base.join(path),
                    faces: None,
                    iterations: None,
                    seed: None,
                    timeout: None,
                    labels: BTreeMap::new(),
                    line,
                })
            })
            .collect::<anyhow::Result<Vec<_>>>()?
    };
    if items.is_empty() {
        bail!("no items");
    }
    let mut seen: HashMap<&str, usize> = HashMap::new();
    for item in &items {
        if let Some(other) = seen.insert(&item.id, item.line) {
            bail!(
                "lines {other} and {} have the same id {:?} (give them distinct ids)",
                item.line,
                item.id
            );
        }
    }
    Ok(items)
}

/// The columns a batch reads itself; every other column is a label.
const COLUMNS: [&str; 6] = ["id", "path", "faces", "iterations", "seed", "timeout"];

/// Refuses a header with an empty column name or one name twice, which would make a field's
/// meaning ambiguous.
fn check_header(header: &[String], line: usize) -> anyhow::Result<()> {
    for (i, name) in header.iter().enumerate() {
        if name.is_empty() {
            bail!("line {line}: column {} has no name", i + 1);
        }
        if header[..i].contains(name) {
            bail!("line {line}: column {name:?} appears twice");
        }
    }
    Ok(())
}

fn parse_table(
    header: &[String],
    rows: &[(usize, &str)],
    delimiter: char,
    base: &Path,
) -> anyhow::Result<Vec<Item>> {
    let column = |name: &str| header.iter().position(|h| h == name);
    let (id_col, path_col) = (column("id"), column("path").expect("checked"));
    let mut items = Vec::with_capacity(rows.len());
    for &(line, row) in rows {
        let fields = split(row, delimiter);
        if fields.len() != header.len() {
            bail!(
                "line {line}: {} fields, the header has {}",
                fields.len(),
                header.len()
            );
        }
        let field = |name: &str| column(name).map(|c| fields[c]).filter(|f| !f.is_empty());
        let at = |e: anyhow::Error| e.context(format!("line {line}"));
        let path = fields[path_col];
        if path.is_empty() {
            bail!("line {line}: empty path");
        }
        let id = match id_col.map(|c| fields[c]).filter(|f| !f.is_empty()) {
            Some(id) => {
                check_id(id).map_err(at)?;
                id.to_string()
            }
            None => id_from_path(path),
        };
        let faces = field("faces")
            .map(|f| parse_budgets(&f.replace(';', " ")))
            .transpose()
            .map_err(at)?;
        let iterations = field("iterations")
            .map(|f| parse_number::<usize>("iterations", f))
            .transpose()
            .map_err(at)?;
        let seed = field("seed")
            .map(|f| parse_number::<u64>("seed", f))
            .transpose()
            .map_err(at)?;
        let timeout = field("timeout")
            .map(|f| parse_seconds(f).map_err(anyhow::Error::msg))
            .transpose()
            .map_err(at)?;
        let labels = header
            .iter()
            .zip(&fields)
            .filter(|(name, field)| !COLUMNS.contains(&name.as_str()) && !field.is_empty())
            .map(|(name, field)| (name.clone(), field.to_string()))
            .collect();
        items.push(Item {
            id,
            input: base.join(path),
            faces,
            iterations,
            seed,
            timeout,
            labels,
            line,
        });
    }
    Ok(items)
}

/// Parses face budgets separated by commas or spaces: every one a positive integer, at least one.
pub fn parse_budgets(text: &str) -> anyhow::Result<Vec<usize>> {
    let budgets = text
        .split([',', ' '])
        .filter(|s| !s.is_empty())
        .map(|s| parse_number::<usize>("faces", s))
        .collect::<anyhow::Result<Vec<_>>>()?;
    if budgets.is_empty() {
        bail!("no face budget in {text:?}");
    }
    if budgets.contains(&0) {
        bail!("a face budget must be positive");
    }
    let mut sorted = budgets.clone();
    sorted.sort_unstable();
    sorted.dedup();
    if sorted.len() != budgets.len() {
        bail!("a face budget is listed twice in {text:?}");
    }
    Ok(budgets)
}

/// Parses a positive, finite number of seconds.
pub fn parse_seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 => Ok(s),
        _ => Err(format!("{text:?} is not a positive number of seconds")),
    }
}

fn parse_number<T: std::str::FromStr>(name: &str, text: &str) -> anyhow::Result<T> {
    text.trim()
        .parse()
        .map_err(|_| anyhow::anyhow!("{name} {text:?} is not a non-negative integer"))
}

fn split(line: &str, delimiter: char) -> Vec<&str> {
    line.split(delimiter).map(|f| unquote(f.trim())).collect()
}

fn unquote(field: &str) -> &str {
    field
        .strip_prefix('"')
        .and_then(|f| f.strip_suffix('"'))
        .unwrap_or(field)
}

/// An id of a manifest's `id` column: letters, digits, `.`, `_`, `-`, not starting with `.`
/// (the batch's temporary files start with one), so it is one safe folder name everywhere.
fn check_id(id: &str) -> anyhow::Result<()> {
    if id.starts_with('.') || !id.chars().all(is_safe) {
        bail!("id {id:?} must be letters, digits, '.', '_' or '-', not starting with '.'");
    }
    Ok(())
}

fn is_safe(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-')
}

/// The id of an item without an `id`: its path as written in the manifest (relative to it),
/// without `.` components, every separator and unsafe character made `_`, leading dots too.
pub fn id_from_path(path: &str) -> String {
    let parts: Vec<String> = Path::new(path)
        .components()
        .filter_map(|c| match c {
            Component::Normal(p) => Some(p.to_string_lossy().into_owned()),
            Component::ParentDir => Some("..".to_string()),
            _ => None,
        })
        .collect();
    let joined = parts.join("_");
    let safe: String = joined
        .chars()
        .map(|c| if is_safe(c) { c } else { '_' })
        .collect();
    let dots = safe.len() - safe.trim_start_matches('.').len();
    format!("{}{}", "_".repeat(dots), &safe[dots..])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plain_list_takes_ids_from_relative_paths() {
        let items =
            parse_manifest("# soups\nchairs/a.obj\n\n../b c.ply\n", Path::new("/m")).unwrap();
        assert_eq!(items.len(), 2);
        assert_eq!(items[0].id, "chairs_a.obj");
        assert_eq!(items[0].input, PathBuf::from("/m/chairs/a.obj"));
        assert_eq!(items[0].line, 2);
        assert_eq!(items[1].id, "___b_c.ply");
    }

    #[test]
    fn a_table_reads_ids_and_overrides() {
        let text = "id,path,faces,iterations,timeout\nx,a.obj,100;200,5,\n,b/c.obj,,,2.5\n";
        let items = parse_manifest(text, Path::new("")).unwrap();
        assert_eq!(items[0].id, "x");
        assert_eq!(items[0].faces, Some(vec![100, 200]));
        assert_eq!(items[0].iterations, Some(5));
        assert_eq!(items[0].timeout, None);
        assert_eq!(items[1].id, "b_c.obj");
        assert_eq!(items[1].timeout, Some(2.5));
        let tsv = parse_manifest("path\tid\na,b.obj\tq\n", Path::new("")).unwrap();
        assert_eq!(tsv[0].input, PathBuf::from("a,b.obj"));
        assert_eq!(tsv[0].id, "q");
    }

    #[test]
    fn bad_manifests_are_refused_with_their_line() {
        let err = |text: &str| format!("{:#}", parse_manifest(text, Path::new("")).unwrap_err());
        assert!(err("").contains("no items"));
        assert!(err("path\n").contains("no items"));
        assert!(err("a_b.obj\na/b.obj\n").contains("lines 1 and 2 have the same id"));
        assert!(err("id,path\nq,a.obj\nq,b.obj\n").contains("same id \"q\""));
        assert!(err("id,path\n../up,a.obj\n").contains("line 2"));
        assert!(
            err("path,colour,colour\na,red,blue\n")
                .contains("line 1: column \"colour\" appears twice")
        );
        assert!(err("# header\npath,,faces\na,red,1\n").contains("line 2: column 2 has no name"));
        assert!(err("path,faces\na,ten\n").contains("line 2"));
        assert!(err("path,faces\na,0\n").contains("positive"));
        assert!(err("path,faces\na\n").contains("1 fields"));
        assert!(err("path,timeout\na,-1\n").contains("seconds"));
    }

    /// The header of the shared corpus manifest.
    const CORPUS_HEADER: &str = "id\tpath\tfamily\tinput_faces\tsource\tvertices\tbytes\t\
        watertight\twinding_consistent\tbodies\tcharacter\tconversion\tsha256";

    #[test]
    fn extra_columns_are_labels_and_input_faces_is_not_a_budget() {
        let text = format!(
            "{CORPUS_HEADER}\n\
             lh_link18\tmeshes/cad/lh_link18.stl\tcad\t3652\tpypi:robosuite\t10956\t182684\t\
             1\t1\t1\tCAD\tverbatim\t9425aea7\n\
             bunny\tmeshes/scan/bunny.ply\tscan\t69451\t\t35947\t3033120\t0\t1\t5\tscan\t\
             ply\t2980b03a\n"
        );
        let items = parse_manifest(&text, Path::new("/corpus")).unwrap();
        assert_eq!(items.len(), 2);
        let cad = &items[0];
        assert_eq!(cad.id, "lh_link18");
        assert_eq!(cad.input, PathBuf::from("/corpus/meshes/cad/lh_link18.stl"));
        assert_eq!(cad.faces, None);
        assert_eq!(cad.labels.len(), 11);
        assert_eq!(cad.labels["family"], "cad");
        assert_eq!(cad.labels["input_faces"], "3652");
        assert_eq!(cad.labels["sha256"], "9425aea7");
        assert!(!cad.labels.contains_key("path") && !cad.labels.contains_key("id"));
        // An empty field is no label.
        assert_eq!(items[1].labels.get("source"), None);
        assert_eq!(items[1].labels["family"], "scan");
    }

    /// The shared corpus manifest, when `ROAR_TEST_DATA` points at the shared meshes beside it.
    #[test]
    fn the_shared_corpus_manifest_loads_with_its_families() {
        let Some(meshes) = std::env::var_os("ROAR_TEST_DATA") else {
            eprintln!("note: ROAR_TEST_DATA unset; skipping the corpus manifest");
            return;
        };
        let path = Path::new(&meshes).join("../corpus/manifest.tsv");
        if !path.is_file() {
            eprintln!("note: no {}; skipping the corpus manifest", path.display());
            return;
        }
        let items = read_manifest(&path).unwrap();
        assert_eq!(items.len(), 250);
        assert!(items.iter().all(|i| i.labels.contains_key("family")));
        assert!(items.iter().all(|i| i.faces.is_none()));
    }

    #[test]
    fn budgets_parse_as_a_list() {
        assert_eq!(parse_budgets("500,1000").unwrap(), vec![500, 1000]);
        assert!(parse_budgets("").is_err());
        assert!(parse_budgets("500,500").is_err());
        assert!(parse_budgets("5x").is_err());
    }
}
