//! Every numeric configuration field against its declared range: NaN, infinities, 0, negative
//! and huge values are refused by `validate` (or by the TOML parser, for whole-number fields)
//! exactly when the range says so, with a message naming the field, the value and the range.

use roar::ReconstructConfig;

/// The default configuration with `key` (`faces`, or `table.leaf` as the ranges name it) set to
/// `value`, parsed as a user's TOML file would be.
fn with(key: &str, value: toml::Value) -> Result<ReconstructConfig, String> {
    let defaults = ReconstructConfig::default();
    let mut table = toml::Table::try_from(&defaults).unwrap();
    match key.split_once('.') {
        Some((stage, leaf)) => {
            let stage = table[stage].as_table_mut().unwrap();
            assert!(stage.contains_key(leaf), "no field {key}");
            stage.insert(leaf.to_string(), value);
        }
        None => {
            table.insert(key.to_string(), value);
        }
    }
    ReconstructConfig::from_toml(&toml::to_string(&table).unwrap(), &defaults)
        .map_err(|e| e.to_string())
}

/// Every scalar of the config's TOML layout by its dotted name (`loss.render_weight`).
fn scalars(config: &ReconstructConfig) -> Vec<(String, toml::Value)> {
    let mut out = Vec::new();
    for (key, value) in toml::Table::try_from(config).unwrap() {
        match value {
            toml::Value::Table(leaves) => out.extend(
                leaves
                    .into_iter()
                    .map(|(leaf, v)| (format!("{key}.{leaf}"), v)),
            ),
            value => out.push((key, value)),
        }
    }
    out
}

#[test]
fn every_numeric_field_has_a_range() {
    let config = ReconstructConfig::default();
    config.validate().unwrap();
    let fields = scalars(&config);
    let ranged: Vec<&str> = config.field_ranges().iter().map(|(r, _)| r.name).collect();
    for (key, value) in &fields {
        if value.is_integer() || value.is_float() {
            assert!(
                ranged.contains(&key.as_str()),
                "{key} has no declared range"
            );
        }
    }
    for name in &ranged {
        assert!(
            fields.iter().any(|(key, _)| key == name),
            "range for unknown field {name}"
        );
    }
}

#[test]
fn every_numeric_field_refuses_values_outside_its_range() {
    let defaults = ReconstructConfig::default();
    let fields = scalars(&defaults);
    for (range, default) in defaults.field_ranges() {
        let integer = fields
            .iter()
            .any(|(key, v)| key == range.name && v.is_integer());
        let leaf = range.name.rsplit('.').next().unwrap();
        let probes = [
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -1.0,
            1e30,
            range.min,
            range.max,
            default,
            range.max * 2.0 + 1.0,
        ];
        for probe in probes {
            let value =
                if integer && probe.is_finite() && probe.fract() == 0.0 && probe.abs() < 9e18 {
                    toml::Value::Integer(probe as i64)
                } else {
                    toml::Value::Float(probe)
                };
            let expected_ok = range.allows(probe) && (!integer || probe.abs() < 9e18);
            let parsed = with(range.name, value.clone());
            if let Err(message) = &parsed {
                // Whole-number fields: the TOML parser refuses fractions, NaN and infinities.
                assert!(
                    !expected_ok,
                    "{} = {probe} did not parse: {message}",
                    range.name
                );
                assert!(message.contains(leaf), "{}: {message}", range.name);
                continue;
            }
            match (
                parsed.unwrap().validate().map_err(|e| e.to_string()),
                expected_ok,
            ) {
                (Ok(()), true) => {}
                (Err(message), true) => {
                    // Allowed by its own range, but in conflict with another field's rule.
                    assert!(
                        message.contains("working_budget_min") && message.contains("above"),
                        "{} = {probe}: {message}",
                        range.name
                    );
                }
                (Ok(()), false) => panic!("{} = {probe} was accepted", range.name),
                (Err(message), false) => {
                    assert!(message.contains(range.name), "{}: {message}", range.name);
                    assert!(message.contains(&probe.to_string()), "{message}");
                    assert_eq!(message.lines().count(), 1, "{message}");
                }
            }
        }
    }
}

#[test]
fn range_errors_name_field_value_and_range() {
    let config = with("loss.render_weight", toml::Value::Float(f64::NAN)).unwrap();
    assert_eq!(
        config.validate().unwrap_err().to_string(),
        "loss.render_weight = NaN is out of range: allowed 0 to 1000000"
    );
    let config = with("finish.sliver_quality", toml::Value::Float(0.5)).unwrap();
    assert!(
        config
            .validate()
            .unwrap_err()
            .to_string()
            .contains("0 (off) or 1 to")
    );
}

#[test]
fn working_budget_bounds_must_be_ordered() {
    let config = with("optimize.working_budget_min", toml::Value::Integer(30_000)).unwrap();
    let message = config.validate().unwrap_err().to_string();
    assert!(message.contains(
        "optimize.working_budget_min = 30000 is above optimize.working_budget_max = 20000"
    ));
}
