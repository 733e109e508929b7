//! The inspection history: an embedded SQLite database in the data folder that indexes every inspected part, its
//! inspections, and the statistics of each instance and profile, for trends across parts. An inspection is entered
//! in one transaction, so a reader (or a daemon killed mid-write) never sees half of one; entering the same job
//! again replaces it, so a job finished twice (its daemon killed between the store and its journal) counts once.
//!
//! The schema is versioned with SQLite's `user_version`: each migration below runs once, in order.

use std::path::{Path, PathBuf};

use rusqlite::{params, Connection, OptionalExtension, Transaction};

use super::PartReport;
use crate::analysis::section::ParameterValue;
use crate::analysis::stats::{DeviationStats, Verdict};
use crate::analysis::tolerances::{Parameter, ParameterVerdict};

/// The store's file in the data folder.
pub const STORE_FILE: &str = "history.sqlite";

/// Migration k brings the schema from version k to k + 1.
const MIGRATIONS: &[&str] = &[
    r#"
    CREATE TABLE parts (
        serial      TEXT PRIMARY KEY,
        part_type   TEXT NOT NULL,
        first_seen  TEXT NOT NULL
    );
    CREATE TABLE inspections (
        id          INTEGER PRIMARY KEY,
        job         TEXT NOT NULL UNIQUE,
        serial      TEXT NOT NULL REFERENCES parts(serial),
        part_type   TEXT NOT NULL,
        started     TEXT NOT NULL,
        finished    TEXT NOT NULL,
        passed      INTEGER NOT NULL,
        lower_mm    REAL NOT NULL,
        upper_mm    REAL NOT NULL,
        report_dir  TEXT NOT NULL
    );
    CREATE TABLE instance_stats (
        inspection  INTEGER NOT NULL REFERENCES inspections(id) ON DELETE CASCADE,
        instance    TEXT NOT NULL,
        points      INTEGER NOT NULL,
        mean_mm     REAL NOT NULL,
        rms_mm      REAL NOT NULL,
        std_mm      REAL NOT NULL,
        min_mm      REAL NOT NULL,
        max_mm      REAL NOT NULL,
        passed      INTEGER NOT NULL,
        PRIMARY KEY (inspection, instance)
    );
    CREATE TABLE profile_stats (
        inspection  INTEGER NOT NULL REFERENCES inspections(id) ON DELETE CASCADE,
        instance    TEXT NOT NULL,
        profile     TEXT NOT NULL,
        x_mm        REAL NOT NULL,
        machine     TEXT NOT NULL,
        points      INTEGER NOT NULL,
        mean_mm     REAL NOT NULL,
        rms_mm      REAL NOT NULL,
        std_mm      REAL NOT NULL,
        min_mm      REAL NOT NULL,
        max_mm      REAL NOT NULL,
        passed      INTEGER NOT NULL,
        PRIMARY KEY (inspection, instance, profile)
    );
    CREATE INDEX inspections_by_serial ON inspections(serial, finished);
    CREATE INDEX inspections_by_type ON inspections(part_type, finished);
"#,
    r#"
    CREATE TABLE rescans (
        inspection  INTEGER NOT NULL REFERENCES inspections(id) ON DELETE CASCADE,
        instance    TEXT NOT NULL,
        profile     TEXT NOT NULL,
        reason      TEXT NOT NULL,
        at          TEXT NOT NULL
    );
    CREATE INDEX rescans_by_profile ON rescans(inspection, instance, profile);
"#,
    // The blade parameters: a section's (instance and profile named), a blade's (profile '') and the part's
    // (instance and profile ''), by the report's key; the limits on the deviation where toleranced.
    r#"
    CREATE TABLE parameters (
        inspection  INTEGER NOT NULL REFERENCES inspections(id) ON DELETE CASCADE,
        instance    TEXT NOT NULL,
        profile     TEXT NOT NULL,
        parameter   TEXT NOT NULL,
        nominal     REAL NOT NULL,
        measured    REAL NOT NULL,
        deviation   REAL NOT NULL,
        lower       REAL,
        upper       REAL,
        passed      INTEGER,
        PRIMARY KEY (inspection, instance, profile, parameter)
    );
"#,
];

/// The history database.
pub struct Store {
    connection: Connection,
    path: PathBuf,
}

/// A store problem, naming the database file.
#[derive(Debug, thiserror::Error)]
#[error("inspection history {path}: {problem}")]
pub struct StoreError {
    pub path: String,
    pub problem: String,
}

/// One profile of one instance in one inspection, as the history holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileRecord {
    pub serial: String,
    pub finished: String,
    pub instance: String,
    pub profile: String,
    pub points: usize,
    pub mean_mm: f64,
    pub rms_mm: f64,
    pub min_mm: f64,
    pub max_mm: f64,
    pub passed: bool,
    /// How many times the profile was scanned again because a scan of it came back with a gap.
    pub rescans: usize,
    /// The inspection's tolerance band, mm.
    pub lower_mm: f64,
    pub upper_mm: f64,
}

/// One parameter of one inspection, as the history holds it: a section's, a blade's (`profile` empty) or the
/// part's (`instance` and `profile` empty).
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterRecord {
    pub serial: String,
    pub finished: String,
    pub instance: String,
    pub profile: String,
    /// The report's key, its unit last (`chord_mm`, `chord_angle_deg`).
    pub parameter: String,
    pub nominal: f64,
    pub measured: f64,
    /// Measured minus nominal.
    pub deviation: f64,
    /// The limits the deviation was held to (lower, upper), where the part gave the parameter a tolerance.
    pub limits: Option<(f64, f64)>,
    pub passed: Option<bool>,
}

impl Store {
    /// Opens (creating if needed) the store at `path` and brings its schema up to date. A store written by a newer
    /// build is refused rather than misread.
    pub fn open(path: &Path) -> Result<Store, StoreError> {
        let fail = |problem: String| StoreError {
            path: path.display().to_string(),
            problem,
        };
        let mut connection = Connection::open(path).map_err(|e| fail(e.to_string()))?;
        connection
            .execute_batch("PRAGMA foreign_keys = ON; PRAGMA journal_mode = WAL;")
            .map_err(|e| fail(e.to_string()))?;
        let version: usize = connection
            .query_row("PRAGMA user_version", [], |row| row.get(0))
            .map_err(|e| fail(e.to_string()))?;
        if version > MIGRATIONS.len() {
            return Err(fail(format!(
                "schema version {version} is newer than this build's {}; use a newer zeroset",
                MIGRATIONS.len()
            )));
        }
        for (k, migration) in MIGRATIONS.iter().enumerate().skip(version) {
            let tx = connection.transaction().map_err(|e| fail(e.to_string()))?;
            tx.execute_batch(migration)
                .and_then(|()| tx.execute_batch(&format!("PRAGMA user_version = {}", k + 1)))
                .and_then(|()| tx.commit())
                .map_err(|e| fail(format!("migration to version {}: {e}", k + 1)))?;
        }
        Ok(Store {
            connection,
            path: path.to_path_buf(),
        })
    }

    fn error(&self, e: rusqlite::Error) -> StoreError {
        StoreError {
            path: self.path.display().to_string(),
            problem: e.to_string(),
        }
    }

    /// Enters an inspection (replacing an earlier entry of the same job) in one transaction.
    pub fn record(&mut self, report: &PartReport, report_dir: &Path) -> Result<(), StoreError> {
        let tx = self.connection.transaction().map_err(|e| StoreError {
            path: self.path.display().to_string(),
            problem: e.to_string(),
        })?;
        let entered = enter(&tx, report, report_dir).and_then(|()| tx.commit());
        entered.map_err(|e| self.error(e))
    }

    /// The report folder of the newest inspection of `serial`.
    pub fn latest_report(&self, serial: &str) -> Result<Option<PathBuf>, StoreError> {
        self.connection
            .query_row(
                "SELECT report_dir FROM inspections WHERE serial = ?1 ORDER BY finished DESC, id DESC LIMIT 1",
                [serial],
                |row| row.get::<_, String>(0),
            )
            .optional()
            .map(|dir| dir.map(PathBuf::from))
            .map_err(|e| self.error(e))
    }

    /// Every profile of the last `last` inspections of a part type, oldest inspection first.
    pub fn profile_history(
        &self,
        part_type: &str,
        last: usize,
    ) -> Result<Vec<ProfileRecord>, StoreError> {
        let mut statement = self
            .connection
            .prepare(
                "SELECT i.serial, i.finished, p.instance, p.profile, p.points, p.mean_mm, p.rms_mm, p.min_mm,
                        p.max_mm, p.passed, i.lower_mm, i.upper_mm,
                        (SELECT COUNT(*) FROM rescans r
                         WHERE r.inspection = p.inspection AND r.instance = p.instance AND r.profile = p.profile)
                 FROM profile_stats p JOIN inspections i ON i.id = p.inspection
                 WHERE i.id IN (SELECT id FROM inspections WHERE part_type = ?1
                                ORDER BY finished DESC, id DESC LIMIT ?2)
                 ORDER BY i.finished, i.id, p.instance, p.x_mm",
            )
            .map_err(|e| self.error(e))?;
        let rows = statement
            .query_map(params![part_type, last as i64], |row| {
                Ok(ProfileRecord {
                    serial: row.get(0)?,
                    finished: row.get(1)?,
                    instance: row.get(2)?,
                    profile: row.get(3)?,
                    points: row.get::<_, i64>(4)? as usize,
                    mean_mm: row.get(5)?,
                    rms_mm: row.get(6)?,
                    min_mm: row.get(7)?,
                    max_mm: row.get(8)?,
                    passed: row.get(9)?,
                    lower_mm: row.get(10)?,
                    upper_mm: row.get(11)?,
                    rescans: row.get::<_, i64>(12)? as usize,
                })
            })
            .map_err(|e| self.error(e))?;
        rows.collect::<Result<_, _>>().map_err(|e| self.error(e))
    }

    /// Every parameter of the last `last` inspections of a part type, oldest inspection first, then by instance,
    /// profile and in the order the report lists them. Inspections entered before parameters were kept have none.
    pub fn parameter_history(
        &self,
        part_type: &str,
        last: usize,
    ) -> Result<Vec<ParameterRecord>, StoreError> {
        let mut statement = self
            .connection
            .prepare(
                "SELECT i.serial, i.finished, p.instance, p.profile, p.parameter, p.nominal, p.measured,
                        p.deviation, p.lower, p.upper, p.passed
                 FROM parameters p JOIN inspections i ON i.id = p.inspection
                 WHERE i.id IN (SELECT id FROM inspections WHERE part_type = ?1
                                ORDER BY finished DESC, id DESC LIMIT ?2)
                 ORDER BY i.finished, i.id, p.rowid",
            )
            .map_err(|e| self.error(e))?;
        let rows = statement
            .query_map(params![part_type, last as i64], |row| {
                let lower: Option<f64> = row.get(8)?;
                let upper: Option<f64> = row.get(9)?;
                Ok(ParameterRecord {
                    serial: row.get(0)?,
                    finished: row.get(1)?,
                    instance: row.get(2)?,
                    profile: row.get(3)?,
                    parameter: row.get(4)?,
                    nominal: row.get(5)?,
                    measured: row.get(6)?,
                    deviation: row.get(7)?,
                    limits: lower.zip(upper),
                    passed: row.get(10)?,
                })
            })
            .map_err(|e| self.error(e))?;
        rows.collect::<Result<_, _>>().map_err(|e| self.error(e))
    }
}

fn enter(tx: &Transaction, report: &PartReport, report_dir: &Path) -> rusqlite::Result<()> {
    tx.execute(
        "INSERT OR IGNORE INTO parts (serial, part_type, first_seen) VALUES (?1, ?2, ?3)",
        params![report.serial, report.part, report.started],
    )?;
    tx.execute("DELETE FROM inspections WHERE job = ?1", [&report.job])?;
    tx.execute(
        "INSERT INTO inspections (job, serial, part_type, started, finished, passed, lower_mm, upper_mm, report_dir)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
        params![
            report.job,
            report.serial,
            report.part,
            report.started,
            report.finished,
            report.verdict.passed(),
            report.tolerance.lower_mm,
            report.tolerance.upper_mm,
            report_dir.display().to_string()
        ],
    )?;
    let inspection = tx.last_insert_rowid();
    for rescan in &report.rescans {
        tx.execute(
            "INSERT INTO rescans (inspection, instance, profile, reason, at) VALUES (?1, ?2, ?3, ?4, ?5)",
            params![inspection, rescan.instance, rescan.profile, rescan.reason, rescan.at],
        )?;
    }
    for instance in &report.instances {
        let s = &instance.stats;
        tx.execute(
            "INSERT INTO instance_stats (inspection, instance, points, mean_mm, rms_mm, std_mm, min_mm, max_mm, passed)
             VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
            params![
                inspection,
                instance.name,
                s.points as i64,
                s.mean_mm,
                s.rms_mm,
                s.std_mm,
                s.min_mm,
                s.max_mm,
                instance.verdict.passed()
            ],
        )?;
        for profile in &instance.profiles {
            insert_profile(
                tx,
                inspection,
                &instance.name,
                profile,
                &profile.stats,
                &profile.verdict,
            )?;
            for (parameter, value) in profile.parameters.iter().flat_map(|p| p.judged()) {
                let place = (instance.name.as_str(), profile.name.as_str());
                insert_parameter(tx, inspection, place, parameter, value)?;
            }
        }
        let blade = [
            (Parameter::BladePitch, &instance.blade_pitch_mm),
            (Parameter::AngularSpacing, &instance.angular_spacing_deg),
        ];
        for (parameter, value) in blade {
            if let Some(value) = value {
                insert_parameter(tx, inspection, (&instance.name, ""), parameter, value)?;
            }
        }
    }
    if let Some(pitch) = &report.propeller_pitch_mm {
        insert_parameter(tx, inspection, ("", ""), Parameter::PropellerPitch, pitch)?;
    }
    Ok(())
}

/// `place` is (instance, profile), either empty where the parameter is a blade's or the part's.
fn insert_parameter(
    tx: &Transaction,
    inspection: i64,
    (instance, profile): (&str, &str),
    parameter: Parameter,
    value: &ParameterValue,
) -> rusqlite::Result<()> {
    tx.execute(
        "INSERT INTO parameters (inspection, instance, profile, parameter, nominal, measured, deviation, lower,
                                 upper, passed)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
        params![
            inspection,
            instance,
            profile,
            parameter.key(),
            value.nominal,
            value.measured,
            value.deviation,
            value.tolerance.map(|t| t.lower),
            value.tolerance.map(|t| t.upper),
            value.verdict.map(|v| v == ParameterVerdict::Pass),
        ],
    )?;
    Ok(())
}

fn insert_profile(
    tx: &Transaction,
    inspection: i64,
    instance: &str,
    profile: &super::ProfileReport,
    s: &DeviationStats,
    verdict: &Verdict,
) -> rusqlite::Result<()> {
    tx.execute(
        "INSERT INTO profile_stats (inspection, instance, profile, x_mm, machine, points, mean_mm, rms_mm, std_mm,
                                    min_mm, max_mm, passed)
         VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)",
        params![
            inspection,
            instance,
            profile.name,
            profile.x_mm,
            profile.machine,
            s.points as i64,
            s.mean_mm,
            s.rms_mm,
            s.std_mm,
            s.min_mm,
            s.max_mm,
            verdict.passed()
        ],
    )?;
    Ok(())
}

#[cfg(test)]
mod tests;
