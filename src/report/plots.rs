//! The report's figures, one SVG string each, drawn with plotters: per profile, every instance's deviation along
//! the section (seed 003's figures 4-6), the sections with their deviations as whiskers along the normals (as
//! measured and after each section's best fit), and their thickness and camber along the chord against nominal.

mod deviation;
mod distribution;
mod section;
mod whiskers;

use plotters::style::RGBColor;

use super::{PartReport, ProfileReport};
use crate::analysis::section::SectionDistribution;
pub use deviation::deviation_svg;
pub use distribution::distribution_svg;
pub use section::{project_section, SectionPoint};
pub use whiskers::whisker_svg;

/// One instance's scan of a profile, projected into the profile's plane.
pub struct InstanceSection<'a> {
    pub instance: &'a str,
    /// The instance's place in the report, so that it keeps its colour in every figure.
    pub colour: RGBColor,
    pub points: Vec<SectionPoint>,
    /// Its thickness and camber along the chord, nominal and measured, where the report has them.
    pub distribution: Option<&'a SectionDistribution>,
}

/// A profile across the instances: the sections that could be projected and the instances whose scan could not
/// (fewer than three points, or all on a line), so that the page can say which are missing from the figures.
pub struct ProfileFigures<'a> {
    pub name: &'a str,
    pub sections: Vec<InstanceSection<'a>>,
    pub unplotted: Vec<&'a str>,
}

/// The profiles of a report by name, in the order they first appear, each with every instance that scanned it.
pub fn profile_figures(report: &PartReport) -> Vec<ProfileFigures<'_>> {
    let mut figures: Vec<ProfileFigures> = Vec::new();
    for (index, instance) in report.instances.iter().enumerate() {
        for profile in &instance.profiles {
            let figure = match figures.iter().position(|f| f.name == profile.name) {
                Some(at) => &mut figures[at],
                None => {
                    figures.push(ProfileFigures {
                        name: &profile.name,
                        sections: Vec::new(),
                        unplotted: Vec::new(),
                    });
                    figures.last_mut().expect("just pushed")
                }
            };
            add_scan(figure, &instance.name, index, profile);
        }
    }
    figures
}

fn add_scan<'a>(
    figure: &mut ProfileFigures<'a>,
    instance: &'a str,
    index: usize,
    profile: &'a ProfileReport,
) {
    match project_section(&profile.points) {
        Some(points) => figure.sections.push(InstanceSection {
            instance,
            colour: instance_colour(index),
            points,
            distribution: profile.distribution.as_ref(),
        }),
        None => figure.unplotted.push(instance),
    }
}

/// The sections as they lie after their least-squares best fits: each point's deviation the one once the
/// section's shift and twist are removed (its form error; 0, drawn as no whisker, where a point has none).
/// `None` when no point has one (older reports, sections that could not be fitted).
pub fn after_best_fit<'a>(sections: &[InstanceSection<'a>]) -> Option<Vec<InstanceSection<'a>>> {
    let fitted = sections
        .iter()
        .flat_map(|s| &s.points)
        .any(|p| p.after_fit_mm.is_some());
    fitted.then(|| {
        sections
            .iter()
            .map(|section| InstanceSection {
                instance: section.instance,
                colour: section.colour,
                distribution: section.distribution,
                points: section
                    .points
                    .iter()
                    .map(|p| SectionPoint {
                        deviation_mm: p.after_fit_mm.unwrap_or(0.0),
                        ..*p
                    })
                    .collect(),
            })
            .collect()
    })
}

/// Okabe and Ito's colour-blind-safe palette (without its yellow, too pale on white), repeated past seven.
const INSTANCE_COLOURS: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(0, 0, 0),
];

fn instance_colour(index: usize) -> RGBColor {
    INSTANCE_COLOURS[index % INSTANCE_COLOURS.len()]
}

/// A figure plotters could not draw.
#[derive(Debug, thiserror::Error)]
#[error("cannot draw the {figure} figure of profile {profile}: {problem}")]
pub struct PlotError {
    pub profile: String,
    pub figure: &'static str,
    pub problem: String,
}

impl PlotError {
    /// Wraps a plotters error met while drawing `figure` for `profile`.
    fn drawing<E: std::fmt::Display>(profile: &str, figure: &'static str) -> impl Fn(E) -> Self {
        let profile = profile.to_string();
        move |problem| PlotError {
            profile: profile.clone(),
            figure,
            problem: problem.to_string(),
        }
    }
}
