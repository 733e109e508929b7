//! Codec throughput in lines per second: decoding scan-point replies (the bulk of the traffic during a scan) and
//! encoding motion commands.
//!
//!     cargo bench -p zeroset-drivers --bench codec

use bytes::BytesMut;
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tokio_util::codec::{Decoder, Encoder};
use zeroset_drivers::codec::{ClientCodec, ServerCodec};
use zeroset_drivers::wire::{Command, Response};

const LINES: usize = 10_000;

fn scan_replies() -> BytesMut {
    let mut bytes = BytesMut::new();
    for i in 0..LINES {
        let x = 100.0 + i as f64 * 0.013;
        let line = format!("00042 # {x:.4}, 212.3456, -35.7810, 0.1234, 0.9876, 0.0956, 0.5\r\n");
        bytes.extend_from_slice(line.as_bytes());
    }
    bytes
}

fn codec(c: &mut Criterion) {
    let replies = scan_replies();
    let mut group = c.benchmark_group("I++ DME codec");
    group.throughput(Throughput::Elements(LINES as u64));
    group.bench_function("decode scan-point replies", |b| {
        b.iter(|| {
            let mut buf = replies.clone();
            let mut codec = ClientCodec::default();
            let mut count = 0;
            while let Some(item) = codec.decode(&mut buf).expect("no I/O error") {
                item.expect("valid line");
                count += 1;
            }
            assert_eq!(count, LINES);
        })
    });
    let commands: Vec<Command> = (0..LINES)
        .map(|i| {
            let line = format!(
                "{:05} GoTo(X({:.4}), Y(212.3456), Z(-35.781))",
                i % 99_999 + 1,
                i as f64 * 0.01
            );
            Command::parse(line.as_bytes()).expect("valid command")
        })
        .collect();
    group.bench_function("encode GoTo commands", |b| {
        b.iter(|| {
            let mut buf = BytesMut::with_capacity(LINES * 48);
            let mut codec = ClientCodec::default();
            for command in &commands {
                codec.encode(command, &mut buf).expect("fits");
            }
            buf.len()
        })
    });
    let responses: Vec<Response> = replies
        .as_ref()
        .split(|b| *b == b'\n')
        .filter(|l| !l.is_empty())
        .map(|l| Response::parse(&l[..l.len() - 1]).expect("valid reply"))
        .collect();
    group.bench_function("encode scan-point replies (simulator side)", |b| {
        b.iter(|| {
            let mut buf = BytesMut::with_capacity(LINES * 64);
            let mut codec = ServerCodec::default();
            for response in &responses {
                codec.encode(response, &mut buf).expect("fits");
            }
            buf.len()
        })
    });
    group.finish();
}

criterion_group!(benches, codec);
criterion_main!(benches);
