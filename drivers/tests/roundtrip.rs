//! Property tests: every value the types can hold formats to a line that parses back to the same value,
//! through the codecs too, and no input makes the decoder panic or lose the lines after a bad one.

use bytes::BytesMut;
use proptest::prelude::*;
use tokio_util::codec::{Decoder, Encoder};
use zeroset_drivers::codec::{ClientCodec, ServerCodec};
use zeroset_drivers::wire::{
    Arg, Call, Command, CommandTag, Data, DeviceError, EventTag, Keyword, LineError, Name, Number,
    Response, ResponseKind, Tag, WireString,
};

fn number() -> impl Strategy<Value = Number> {
    let from_value = any::<f64>().prop_filter_map("finite", |value| Number::from_f64(value).ok());
    // Texts in every form the spec allows; those past the range of f64 are rejected, so filtered out.
    let from_text = "[+-]?([0-9]{1,8}(\\.[0-9]{0,8})?|\\.[0-9]{1,8})([eE][+-]?[0-9]{1,3})?"
        .prop_filter_map("in f64 range", |text| text.parse().ok());
    prop_oneof![from_value, from_text]
}

fn wire_string() -> impl Strategy<Value = WireString> {
    "[ !#-~]{1,24}"
        .prop_map(|text| WireString::new(&text).expect("generated from the allowed characters"))
}

fn name_text() -> impl Strategy<Value = String> {
    "[A-Za-z][A-Za-z0-9]{0,8}(\\.[A-Za-z][A-Za-z0-9]{0,8}){0,3}"
}

fn name() -> impl Strategy<Value = Name> {
    name_text().prop_map(|text| Name::new(&text).expect("generated as a name"))
}

fn event_tag() -> impl Strategy<Value = EventTag> {
    (1..=9999u16).prop_map(|number| EventTag::new(number).expect("in range"))
}

fn command_tag() -> impl Strategy<Value = CommandTag> {
    (1..=99_999u32).prop_map(|number| CommandTag::new(number).expect("in range"))
}

fn arg() -> impl Strategy<Value = Arg> {
    let leaf = prop_oneof![
        number().prop_map(Arg::Number),
        wire_string().prop_map(Arg::String),
        event_tag().prop_map(Arg::EventTag),
        "[A-Za-z][A-Za-z0-9]{0,8}"
            .prop_filter_map("not an event tag", |text| Keyword::new(&text).ok())
            .prop_map(Arg::Keyword),
    ];
    // Three levels inside a command's own parentheses: as deep as ScanOnCurve(Format(X())) and more.
    leaf.prop_recursive(3, 24, 5, |inner| {
        (name(), prop::collection::vec(inner, 0..5))
            .prop_map(|(name, args)| Arg::Call(Call::new(name, args)))
    })
}

fn command() -> impl Strategy<Value = Command> {
    let tag = prop_oneof![
        command_tag().prop_map(Tag::Command),
        event_tag().prop_map(Tag::Event)
    ];
    (tag, name_text(), prop::collection::vec(arg(), 0..6)).prop_map(|(tag, mut name, args)| {
        // Fast-queue commands end in `E` and only they take event tags.
        match tag {
            Tag::Event(_) => name.push('E'),
            _ if name.ends_with('E') => name.push('x'),
            _ => {}
        }
        Command::new(tag, Name::new(&name).expect("a name"), args).expect("a valid command")
    })
}

fn call() -> impl Strategy<Value = Call> {
    (name(), prop::collection::vec(arg(), 0..5)).prop_map(|(name, args)| Call::new(name, args))
}

fn data() -> impl Strategy<Value = Data> {
    prop_oneof![
        prop::collection::vec(number(), 1..40).prop_map(Data::Numbers),
        prop::collection::vec(wire_string(), 1..4).prop_map(Data::Strings),
        prop::collection::vec(call(), 1..6).prop_map(Data::Calls),
        prop::collection::vec(number(), 1..7).prop_map(Data::Vector),
    ]
}

fn device_error() -> impl Strategy<Value = DeviceError> {
    (0..=9u8, 0..=9999u16, wire_string(), wire_string()).prop_map(
        |(severity, code, command, text)| {
            DeviceError::new(severity, code, command, text).expect("in range")
        },
    )
}

fn response() -> impl Strategy<Value = Response> {
    let any_tag = prop_oneof![
        command_tag().prop_map(Tag::Command),
        event_tag().prop_map(Tag::Event),
        Just(Tag::Unsolicited)
    ];
    let transaction_tag = prop_oneof![
        command_tag().prop_map(Tag::Command),
        event_tag().prop_map(Tag::Event)
    ];
    prop_oneof![
        (transaction_tag.clone(), Just(ResponseKind::Ack)),
        (transaction_tag, Just(ResponseKind::Complete)),
        (any_tag.clone(), data().prop_map(ResponseKind::Data)),
        (any_tag, device_error().prop_map(ResponseKind::Error)),
    ]
    .prop_map(|(tag, kind)| Response::new(tag, kind).expect("a valid response"))
}

/// Decodes `bytes` delivered in two reads split at `split`, then the end of the stream.
fn decode_in_two_reads<D, T>(mut codec: D, bytes: &[u8], split: usize) -> Vec<Result<T, LineError>>
where
    D: Decoder<Item = Result<T, LineError>, Error = std::io::Error>,
{
    let split = split % (bytes.len() + 1);
    let mut buf = BytesMut::from(&bytes[..split]);
    let mut items = Vec::new();
    while let Some(item) = codec.decode(&mut buf).unwrap() {
        items.push(item);
    }
    buf.extend_from_slice(&bytes[split..]);
    while let Some(item) = codec.decode_eof(&mut buf).unwrap() {
        items.push(item);
    }
    items
}

proptest! {
    #[test]
    fn commands_read_back_as_written(command in command()) {
        let line = command.to_string();
        prop_assert_eq!(line.parse::<Command>(), Ok(command));
    }

    #[test]
    fn responses_read_back_as_written(response in response()) {
        let line = response.to_string();
        prop_assert_eq!(line.parse::<Response>(), Ok(response));
    }

    #[test]
    fn commands_cross_the_codecs(commands in prop::collection::vec(command(), 1..8), split in any::<usize>()) {
        let mut bytes = BytesMut::new();
        for command in &commands {
            ClientCodec::default().encode(command, &mut bytes).unwrap();
        }
        let decoded: Vec<Command> = decode_in_two_reads(ServerCodec::default(), &bytes, split).into_iter().map(Result::unwrap).collect();
        prop_assert_eq!(decoded, commands);
    }

    #[test]
    fn responses_cross_the_codecs(responses in prop::collection::vec(response(), 1..8), split in any::<usize>()) {
        let mut bytes = BytesMut::new();
        for response in &responses {
            ServerCodec::default().encode(response, &mut bytes).unwrap();
        }
        let decoded: Vec<Response> = decode_in_two_reads(ClientCodec::default(), &bytes, split).into_iter().map(Result::unwrap).collect();
        prop_assert_eq!(decoded, responses);
    }

    #[test]
    fn numbers_keep_their_value(value in any::<f64>().prop_filter("finite", |value| value.is_finite())) {
        let number = Number::from_f64(value).unwrap();
        // Rounding to 16 significant digits moves a value by at most half a unit in the 16th digit, plus
        // the rounding of reading it back.
        prop_assert!((number.value() - value).abs() <= value.abs() * 6e-16, "{} for {}", number, value);
        prop_assert_eq!(number.as_str().parse::<Number>(), Ok(number));
    }

    #[test]
    fn cmm_values_are_exact_and_plain(thousandths in -999_999_999i64..999_999_999) {
        let value = thousandths as f64 / 1000.0;
        let number = Number::from_f64(value).unwrap();
        prop_assert_eq!(number.value(), value);
        prop_assert!(!number.as_str().contains('E'), "{} has an exponent", number);
    }

    #[test]
    fn any_bytes_decode_without_panic_and_the_next_line_survives(garbage in prop::collection::vec(any::<u8>(), 0..300)) {
        let mut bytes = garbage;
        bytes.extend_from_slice(b"\r\n00007 Home()\r\n");
        let items = decode_in_two_reads(ServerCodec::default(), &bytes, 0);
        let last = items.last().unwrap().as_ref().map(ToString::to_string);
        prop_assert_eq!(last, Ok("00007 Home()".to_owned()));
    }
}
