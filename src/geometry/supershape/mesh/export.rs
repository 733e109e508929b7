//! Mesh encodings: binary STL (stl_io), binary little-endian PLY (ply-rs-bw) and Wavefront OBJ (a few
//! lines of text, no crate needed). Coordinates are millimetres; PLY and OBJ say so in a comment,
//! binary STL in its free-text 80-byte header. The kernel does no file I/O: meshes are written to any
//! `io::Write`, and the caller owns the file (the CLI writes it atomically).

use std::io::Write;
use std::path::Path;

use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
    ScalarType,
};

use super::trimesh::TriMesh;
use super::MeshError;

/// The mesh file formats the station writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MeshFormat {
    Stl,
    Ply,
    Obj,
}

const UNITS: &str = "units: mm";

impl MeshFormat {
    /// The format named by a path's extension (case-insensitive .stl, .ply, .obj).
    pub fn from_path(path: &Path) -> Result<Self, MeshError> {
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match extension.as_deref() {
            Some("stl") => Ok(Self::Stl),
            Some("ply") => Ok(Self::Ply),
            Some("obj") => Ok(Self::Obj),
            _ => Err(MeshError::UnknownFormat {
                path: path.display().to_string(),
            }),
        }
    }
}

impl TriMesh {
    /// Writes the mesh to `out` in `format` (many small writes for OBJ: buffer a slow `out`).
    pub fn write_to<W: Write>(&self, out: &mut W, format: MeshFormat) -> Result<(), MeshError> {
        match format {
            MeshFormat::Stl => self.write_stl(out),
            MeshFormat::Ply => self.write_ply(out),
            MeshFormat::Obj => self.write_obj(out),
        }
    }

    /// Binary STL: single-precision triangles with their unit normals (the format holds no shared
    /// vertices and no better precision).
    fn write_stl<W: Write>(&self, out: &mut W) -> Result<(), MeshError> {
        let triangles: Vec<stl_io::Triangle> = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices[v as usize]);
                let normal = (b - a)
                    .cross(&(c - a))
                    .try_normalize(0.0)
                    .unwrap_or_default();
                stl_io::Triangle {
                    normal: stl_io::Normal::new([
                        normal.x as f32,
                        normal.y as f32,
                        normal.z as f32,
                    ]),
                    vertices: [a, b, c]
                        .map(|p| stl_io::Vertex::new([p.x as f32, p.y as f32, p.z as f32])),
                }
            })
            .collect();
        // Built in memory because stl_io writes a blank header, replaced here by free text that must not
        // start with "solid" (the ASCII format's keyword).
        let mut bytes = Vec::new();
        stl_io::write_stl(&mut bytes, triangles.iter())?;
        let header = format!("binary STL from zeroset, {UNITS}");
        bytes[..header.len()].copy_from_slice(header.as_bytes());
        out.write_all(&bytes)?;
        Ok(())
    }

    /// Binary little-endian PLY with double-precision vertices and triangle index lists.
    fn write_ply<W: Write>(&self, out: &mut W) -> Result<(), MeshError> {
        let mut ply = Ply::<DefaultElement>::new();
        ply.header.encoding = Encoding::BinaryLittleEndian;
        ply.header.comments.push(UNITS.to_string());
        let mut vertex = ElementDef::new("vertex".to_string());
        for name in ["x", "y", "z"] {
            vertex.properties.add(PropertyDef::new(
                name.to_string(),
                PropertyType::Scalar(ScalarType::Double),
            ));
        }
        ply.header.elements.add(vertex);
        let mut face = ElementDef::new("face".to_string());
        face.properties.add(PropertyDef::new(
            "vertex_indices".to_string(),
            PropertyType::List(ScalarType::UChar, ScalarType::UInt),
        ));
        ply.header.elements.add(face);
        let vertices = self
            .vertices
            .iter()
            .map(|p| {
                let mut element = DefaultElement::new();
                for (name, value) in [("x", p.x), ("y", p.y), ("z", p.z)] {
                    element.insert(name.to_string(), Property::Double(value));
                }
                element
            })
            .collect();
        let faces = self
            .triangles
            .iter()
            .map(|t| {
                let mut element = DefaultElement::new();
                element.insert("vertex_indices".to_string(), Property::ListUInt(t.to_vec()));
                element
            })
            .collect();
        ply.payload.insert("vertex".to_string(), vertices);
        ply.payload.insert("face".to_string(), faces);
        ply_rs_bw::writer::Writer::new().write_ply(out, &mut ply)?;
        Ok(())
    }

    /// Wavefront OBJ: `v x y z` with the shortest decimal that reads back to the same double,
    /// `f a b c` with 1-based indices.
    fn write_obj<W: Write>(&self, out: &mut W) -> Result<(), MeshError> {
        writeln!(out, "# zeroset mesh, {UNITS}")?;
        for p in &self.vertices {
            writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for t in &self.triangles {
            writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::{polygonise, MeshParams};
    use super::*;
    use crate::geometry::supershape::csg::{Node, Solid};
    use crate::geometry::supershape::deform::{Deformation, Deformations};
    use crate::geometry::supershape::shape::Supershape;
    use nalgebra::Point3;

    fn ellipsoid_mesh() -> TriMesh {
        let solid = Solid::new(Node::supershape(
            Supershape {
                scale: [7.0, 5.0, 4.0],
                ..Supershape::sphere()
            },
            Deformations(vec![Deformation::Twist { rate: 0.05 }]),
        ));
        polygonise(&solid, &MeshParams::with_cell(1.5)).unwrap()
    }

    /// A minimal OBJ reader for the round trip: `v` and triangular `f` lines.
    fn read_obj(text: &str) -> TriMesh {
        let mut mesh = TriMesh::default();
        for line in text.lines() {
            let mut fields = line.split_whitespace();
            match fields.next() {
                Some("v") => {
                    let c: Vec<f64> = fields.map(|f| f.parse().unwrap()).collect();
                    mesh.vertices.push(Point3::new(c[0], c[1], c[2]));
                }
                Some("f") => {
                    let i: Vec<u32> = fields.map(|f| f.parse::<u32>().unwrap() - 1).collect();
                    mesh.triangles.push([i[0], i[1], i[2]]);
                }
                _ => {}
            }
        }
        mesh
    }

    fn encoded(mesh: &TriMesh, format: MeshFormat) -> Vec<u8> {
        let mut bytes = Vec::new();
        mesh.write_to(&mut bytes, format).unwrap();
        bytes
    }

    #[test]
    fn formats_follow_the_extension() {
        assert_eq!(
            MeshFormat::from_path(Path::new("a/b.STL")).unwrap(),
            MeshFormat::Stl
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("b.ply")).unwrap(),
            MeshFormat::Ply
        );
        assert_eq!(
            MeshFormat::from_path(Path::new("b.obj")).unwrap(),
            MeshFormat::Obj
        );
        let err = MeshFormat::from_path(Path::new("b.step"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("b.step"), "{err}");
    }

    #[test]
    fn obj_reads_back_exactly() {
        let mesh = ellipsoid_mesh();
        let text = String::from_utf8(encoded(&mesh, MeshFormat::Obj)).unwrap();
        assert!(text.starts_with("# zeroset mesh, units: mm"));
        assert_eq!(read_obj(&text), mesh);
    }

    #[test]
    fn ply_reads_back_exactly() {
        let mesh = ellipsoid_mesh();
        let bytes = encoded(&mesh, MeshFormat::Ply);
        let ply = ply_rs_bw::parser::Parser::<DefaultElement>::new()
            .read_ply(&mut bytes.as_slice())
            .unwrap();
        assert_eq!(ply.header.comments, vec![UNITS.to_string()]);
        let coordinate = |e: &DefaultElement, name: &str| match e[name] {
            Property::Double(v) => v,
            ref other => panic!("{name}: {other:?}"),
        };
        let vertices: Vec<Point3<f64>> = ply.payload["vertex"]
            .iter()
            .map(|e| Point3::new(coordinate(e, "x"), coordinate(e, "y"), coordinate(e, "z")))
            .collect();
        let triangles: Vec<[u32; 3]> = ply.payload["face"]
            .iter()
            .map(|e| match &e["vertex_indices"] {
                Property::ListUInt(i) => [i[0], i[1], i[2]],
                other => panic!("{other:?}"),
            })
            .collect();
        assert_eq!(
            TriMesh {
                vertices,
                triangles
            },
            mesh
        );
    }

    #[test]
    fn stl_reads_back_to_single_precision() {
        let mesh = ellipsoid_mesh();
        let bytes = encoded(&mesh, MeshFormat::Stl);
        assert!(bytes.starts_with(b"binary STL from zeroset, units: mm"));
        let read = stl_io::read_stl(&mut std::io::Cursor::new(bytes)).unwrap();
        assert_eq!(read.faces.len(), mesh.triangles.len());
        // stl_io merges identical single-precision positions back into shared vertices.
        let distinct: std::collections::HashSet<[u32; 3]> = mesh
            .vertices
            .iter()
            .map(|p| [p.x as f32, p.y as f32, p.z as f32].map(f32::to_bits))
            .collect();
        assert_eq!(read.vertices.len(), distinct.len());
        for (face, t) in read.faces.iter().zip(&mesh.triangles) {
            for (&read_index, &index) in face.vertices.iter().zip(t) {
                let expected = mesh.vertices[index as usize];
                let got = read.vertices[read_index].0;
                assert_eq!(got, [expected.x, expected.y, expected.z].map(|c| c as f32));
            }
        }
    }
}
