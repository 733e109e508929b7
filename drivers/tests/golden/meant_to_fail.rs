//! Which NIST lines are meant to fail, from NIST's descriptions, and which layer must catch them.
//!
//! NIST's parsers check two things at once: the spec's syntax (6.1.1, 6.2 and the grammar of 6.1.4.2)
//! and what each command and reply may contain. The wire codec does the first; the second belongs to the
//! layer that knows the commands (a later task). So every line NIST's descriptions list as an error is
//! here with NIST's own message, quoted from the .txt file, and one of:
//!
//! - `rejected`: the line breaks the syntax, and the codec must report the problem named (the start of
//!   the `WireError` variant's name);
//! - `command`: the line is well-formed I++ (a known shape of tag, name, parentheses, numbers, strings) but
//!   wrong for that command or reply: argument count or kind (`AbortE(3)`), a property used twice, a value
//!   out of range, an unknown keyword. The codec must accept it, so that the command layer sees it.
//!
//! Two kinds of NIST complaint the spec does not support are `command` too: properties with non-number
//! arguments (`X("oops")`; the spec's grammar allows only numbers there, but valid replies such as
//! `Tool.Name("Probe1")` break that rule, so the codec takes any argument), and error replies whose code,
//! text or severity disagree with NIST's table (1.4.3 lets servers adapt severities and define codes
//! 8000-8999, and NIST's own server sends "Incorrect Arguments" for the spec's "Incorrect arguments").

/// The layer that must reject a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layer {
    /// The codec, with a problem whose variant name starts with this.
    Wire(&'static str),
    /// The command layer; the codec accepts the line.
    Command,
}

/// A line NIST meant to fail: its first line as written in the file, and NIST's message.
#[derive(Debug)]
pub struct MeantToFail {
    pub line: &'static str,
    pub nist_says: &'static str,
    pub layer: Layer,
}

const fn rejected(
    line: &'static str,
    nist_says: &'static str,
    problem: &'static str,
) -> MeantToFail {
    MeantToFail {
        line,
        nist_says,
        layer: Layer::Wire(problem),
    }
}

const fn command(line: &'static str, nist_says: &'static str) -> MeantToFail {
    MeantToFail {
        line,
        nist_says,
        layer: Layer::Command,
    }
}

/// The table for a file, and whether NIST meant every line of it to fail.
pub fn table(file_name: &str) -> (&'static [MeantToFail], bool) {
    match file_name {
        "parserCmdErrors.prg" => (PARSER_CMD_ERRORS, false),
        "parserResErrors.res" => (PARSER_RES_ERRORS, true),
        "numbersErrorCmd.prg" => (NUMBERS_ERROR_CMD, false),
        "numbersErrorRes.res" => (NUMBERS_ERROR_RES, true),
        "checkerCmdErrors.prg" => (CHECKER_CMD_ERRORS, false),
        _ => (&[], false),
    }
}

/// parserCmdErrors.txt: "The parserCmdErrors.prg file was designed to trigger all the source lines of the
/// form "errorCode = XXX;" [of] parserCmd.cc". Its StartSession, EndSession and the ClearAllErrors between
/// the tests are valid.
const PARSER_CMD_ERRORS: &[MeantToFail] = &[
    command("E0101 AbortE(3)", "AbortE: MUST HAVE NO ARGUMENTS"),
    command(
        "00201 AlignPart(0, -1)",
        "AlignPart: MUST HAVE 7 OR 14 ARGUMENTS",
    ),
    rejected(
        r#"00202 AlignPart(0"oops"-1, 0, 0.6, 0.0, 0.8, 1.0)"#,
        "AlignPart: BAD ARGUMENTS",
        "Expected",
    ),
    rejected(
        r#"00203 AlignPart(1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0"oops"2.0)"#,
        "AlignPart: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "00301 AlignTool(0, 1, 30)",
        "AlignTool: MUST HAVE 4 OR 8 ARGUMENTS",
    ),
    rejected(
        r#"00302 AlignTool(1"oops"0, 0, 45)"#,
        "AlignTool: BAD ARGUMENTS",
        "Expected",
    ),
    rejected(
        r#"00303 AlignTool(0, -1, 0, 0.6, 0.0, 0.8, 30"oops"45)"#,
        "AlignTool: BAD ARGUMENTS",
        "Expected",
    ),
    command("00401 CenterPart(1)", "CenterPart: MUST HAVE 4 ARGUMENTS"),
    command(
        r#"00402 CenterPart(1, 2, 3, "four")"#,
        "CenterPart: BAD ARGUMENTS",
    ),
    command(
        r#"00501 ChangeTool("one","two")"#,
        "ChangeTool: MUST HAVE ONE ARGUMENT",
    ),
    command("00502 ChangeTool(3)", "ChangeTool: ARGUMENT MUST BE STRING"),
    command(
        r#"00601 ClearAllErrors("Now!")"#,
        "ClearAllErrors: MUST HAVE NO ARGUMENTS",
    ),
    rejected(
        "00701 DisableUser(,)",
        "DisableUser: MUST HAVE NO ARGUMENTS",
        "Expected",
    ),
    command("00801 EnableUser(2)", "EnableUser: MUST HAVE NO ARGUMENTS"),
    command("00901 EndSession(2)", "EndSession: MUST HAVE NO ARGUMENTS"),
    command("01001 EnumAllProp(Tool)", "EnumAllProp: BAD ARGUMENTS"),
    command(
        "01002 EnumAllProp(Speed())",
        "EnumAllProp: ARGUMENT FIRST PART MUST BE TOOL OR FOUNDTOOL",
    ),
    rejected(
        "01003 EnumAllProp(Tool , )",
        "EnumAllProp: ARGUMENT MUST END WITH EMPTY PARENTHESES",
        "Expected",
    ),
    command("01004 EnumAllProp(Tool,GoToPar())", "EnumAllProp: BAD DOTS"),
    command(
        "01005 EnumAllProp(Tool.Speed())",
        "EnumAllProp: ARGUMENT SECOND PART MUST BE GOTOPAR OR PTMEASPAR",
    ),
    command(
        "01006 EnumAllProp(Tool.GoToPar.Tool())",
        "EnumAllProp: ARGUMENT THIRD PART BAD",
    ),
    command(
        "01007 EnumAllProp(Tool.GoToPar.Speed.Name())",
        "EnumAllProp: ARGUMENT FOURTH PART BAD",
    ),
    command("01101 EnumProp(Tool)", "EnumProp: BAD ARGUMENTS"),
    command(
        "01102 EnumProp(Speed())",
        "EnumProp: ARGUMENT FIRST PART MUST BE TOOL OR FOUNDTOOL",
    ),
    rejected(
        "01103 EnumProp(Tool , )",
        "EnumProp: ARGUMENT MUST END WITH EMPTY PARENTHESES",
        "Expected",
    ),
    command("01104 EnumProp(Tool,GoToPar())", "EnumProp: BAD DOTS"),
    command(
        "01105 EnumProp(Tool.Speed())",
        "EnumProp: ARGUMENT SECOND PART MUST BE GOTOPAR OR PTMEASPAR",
    ),
    command(
        "01106 EnumProp(Tool.GoToPar.Tool())",
        "EnumProp: ARGUMENT THIRD PART BAD",
    ),
    command(
        "01107 EnumProp(Tool.GoToPar.Accel.Id())",
        "EnumProp: ARGUMENT FOURTH PART BAD",
    ),
    command("01201 EnumTools(2)", "EnumTools: MUST HAVE NO ARGUMENTS"),
    command("01301 FindTool()", "FindTool: MUST HAVE ONE ARGUMENT"),
    command("01302 FindTool(1)", "FindTool: ARGUMENT MUST BE STRING"),
    command("01401 Get(X)", "Get: BAD ARGUMENTS"),
    command("01402 Get(X() , Y)", "Get: BAD ARGUMENTS"),
    rejected("01403 Get(X() , Y,)", "Get: BAD ARGUMENTS", "Expected"),
    command("01404 Get(R(), R())", "Get: R ARGUMENT USED TWICE"),
    command("01405 Get(X(), X())", "Get: X ARGUMENT USED TWICE"),
    command("01406 Get(Y(), Y())", "Get: Y ARGUMENT USED TWICE"),
    command("01407 Get(Z(), Z())", "Get: Z ARGUMENT USED TWICE"),
    command("01408 Get(Tool())", "Get: BAD ARGUMENTS"),
    command(
        "01409 Get(Tool.A(), Tool.A())",
        "Get: TOOL A ARGUMENT USED TWICE",
    ),
    command(
        "01410 Get(Tool.B(), Tool.B())",
        "Get: TOOL B ARGUMENT USED TWICE",
    ),
    command(
        "01411 Get(Tool.C(), Tool.C())",
        "Get: TOOL C ARGUMENT USED TWICE",
    ),
    command("01412 Get(Tool.Q())", "Get: BAD ARGUMENTS"),
    command("01413 Get(Q())", "Get: BAD ARGUMENTS"),
    command(
        "01501 GetChangeToolAction()",
        "GetChangeToolAction: MUST HAVE ONE ARGUMENT",
    ),
    command(
        "01502 GetChangeToolAction(3)",
        "GetChangeToolAction: ARGUMENT MUST BE STRING",
    ),
    command(
        "01601 GetCoordSystem(MachineCsy)",
        "GetCoordSystem: MUST HAVE NO ARGUMENTS",
    ),
    command(
        "01701 GetCsyTransformation()",
        "GetCsyTransformation: MUST HAVE ONE ARGUMENT",
    ),
    command(
        "01702 GetCsyTransformation(MachineCsy)",
        "GetCsyTransformation: BAD ARGUMENTS",
    ),
    command(
        "01801 GetDMEVersion(2)",
        "GetDMEVersion: MUST HAVE NO ARGUMENTS",
    ),
    command(
        "01901 GetErrorInfo()",
        "GetErrorInfo: MUST HAVE ONE ARGUMENT",
    ),
    command(
        "01902 GetErrorInfo(2.7)",
        "GetErrorInfo: ARGUMENT MUST BE INTEGER",
    ),
    command(
        "E2001 GetErrStatusE(1)",
        "GetErrStatusE: MUST HAVE NO ARGUMENTS",
    ),
    command(
        "02101 GetMachineClass(1)",
        "GetMachineClass: MUST HAVE NO ARGUMENTS",
    ),
    command(
        "02201 GetProp(FoundTool.PtMeasPar.Accel(), Tool)",
        "GetProp: BAD ARGUMENTS",
    ),
    command(
        "02202 GetProp(Speed.PtMeasPar.Accel())",
        "GetProp: ARGUMENT FIRST PART MUST BE TOOL OR FOUNDTOOL",
    ),
    command("02203 GetProp(Tool,PtMeasPar.Accel())", "GetProp: BAD DOTS"),
    command(
        "02204 GetProp(Tool.X.Accel())",
        "GetProp: ARGUMENT SECOND PART BAD",
    ),
    command(
        "02205 GetProp(FoundTool.Alignment())",
        "GetProp: BAD ARGUMENTS",
    ),
    command(
        "02206 GetProp(Tool.Speed())",
        "GetProp: ARGUMENT SECOND PART BAD",
    ),
    command(
        "02207 GetProp(Tool.Accel.Accel())",
        "GetProp: ARGUMENT SECOND PART BAD",
    ),
    rejected(
        "02208 GetProp(Tool.PtMeasPar,Speed())",
        "GetProp: BAD DOTS",
        "Expected",
    ),
    rejected(
        "02209 GetProp(Tool.PtMeasPar.Accel.Max)",
        "GetProp: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "02210 GetProp(FoundTool.PtMeasPar.Dis())",
        "GetProp: ARGUMENT THIRD PART BAD",
    ),
    rejected(
        "02211 GetProp(Tool.PtMeasPar.Speed,Max())",
        "GetProp: BAD DOTS",
        "Expected",
    ),
    rejected(
        "02212 GetProp(Tool.PtMeasPar.Speed.Max)",
        "GetProp: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "02213 GetProp(Tool.PtMeasPar.Speed.Dis())",
        "GetProp: ARGUMENT FOURTH PART BAD",
    ),
    rejected(
        "02214 GetProp(Tool.PtMeasPar.Speed.Max,)",
        "GetProp: ARGUMENT MUST END WITH EMPTY PARENTHESES",
        "Expected",
    ),
    rejected(
        "02215 GetProp(Tool.PtMeasPar.Speed.Max()())",
        "GetProp: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "E2301 GetPropE(FoundTool.PtMeasPar.Accel(), Tool)",
        "GetPropE: BAD ARGUMENTS",
    ),
    command(
        "E2302 GetPropE(Speed.PtMeasPar.Accel())",
        "GetPropE: ARGUMENT FIRST PART MUST BE TOOL OR FOUNDTOOL",
    ),
    command(
        "E2303 GetPropE(Tool,PtMeasPar.Accel())",
        "GetPropE: BAD DOTS",
    ),
    command(
        "E2304 GetPropE(Tool.X.Accel())",
        "GetPropE: ARGUMENT SECOND PART BAD",
    ),
    command(
        "E2305 GetPropE(FoundTool.Alignment())",
        "GetPropE: BAD ARGUMENTS",
    ),
    command(
        "E2306 GetPropE(Tool.Speed())",
        "GetPropE: ARGUMENT SECOND PART BAD",
    ),
    command(
        "E2307 GetPropE(Tool.Accel.Accel())",
        "GetPropE: ARGUMENT SECOND PART BAD",
    ),
    rejected(
        "E2308 GetPropE(Tool.PtMeasPar,Speed())",
        "GetPropE: BAD DOTS",
        "Expected",
    ),
    rejected(
        "E2309 GetPropE(Tool.PtMeasPar.Accel.Max)",
        "GetPropE: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "E2310 GetPropE(FoundTool.PtMeasPar.Dis())",
        "GetPropE: ARGUMENT THIRD PART BAD",
    ),
    rejected(
        "E2311 GetPropE(Tool.PtMeasPar.Speed,Max())",
        "GetPropE: BAD DOTS",
        "Expected",
    ),
    rejected(
        "E2312 GetPropE(Tool.PtMeasPar.Speed.Max)",
        "GetPropE: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "E2313 GetPropE(Tool.PtMeasPar.Speed.Dis())",
        "GetPropE: ARGUMENT FOURTH PART BAD",
    ),
    rejected(
        "E2314 GetPropE(Tool.PtMeasPar.Speed.Max,)",
        "GetPropE: ARGUMENT MUST END WITH EMPTY PARENTHESES",
        "Expected",
    ),
    rejected(
        "E2315 GetPropE(Tool.PtMeasPar.Speed.Max()())",
        "GetPropE: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "02401 GetXtdErrStatus(1)",
        "GetXtdErrStatus: MUST HAVE NO ARGUMENTS",
    ),
    command("02501 GoTo(10.7)", "GoTo: BAD ARGUMENTS"),
    rejected("02502 GoTo(10,)", "GoTo: BAD ARGUMENTS", "Expected"),
    command("02503 GoTo(X())", "GoTo: BAD ARGUMENTS"),
    command("02504 GoTo(X(4), X(4))", "GoTo: X ARGUMENT USED TWICE"),
    command("02505 GoTo(Y(4), Y(4))", "GoTo: Y ARGUMENT USED TWICE"),
    command("02506 GoTo(Z(4), Z(4))", "GoTo: Z ARGUMENT USED TWICE"),
    command("02507 GoTo(Tool.A())", "GoTo: BAD ARGUMENTS"),
    command(
        "02508 GoTo(Tool.A(1), Tool.A(2))",
        "GoTo: TOOL A ARGUMENT USED TWICE",
    ),
    command(
        "02509 GoTo(Tool.B(1), Tool.B(2))",
        "GoTo: TOOL B ARGUMENT USED TWICE",
    ),
    command(
        "02510 GoTo(Tool.C(1), Tool.C(2))",
        "GoTo: TOOL C ARGUMENT USED TWICE",
    ),
    command("02511 GoTo(Q(3))", "GoTo: BAD ARGUMENTS"),
    command("02601 Home(1)", "Home: MUST HAVE NO ARGUMENTS"),
    command("02701 IsHomed(1)", "IsHomed: MUST HAVE NO ARGUMENTS"),
    command(
        "02801 IsUserEnabled(1)",
        "IsUserEnabled: MUST HAVE NO ARGUMENTS",
    ),
    command("02901 LockAxis()", "LockAxis: BAD ARGUMENTS"),
    command("02902 LockAxis(X(1))", "LockAxis: BAD ARGUMENTS"),
    command(
        "02903 LockAxis(C(), C())",
        "LockAxis: C ARGUMENT USED TWICE",
    ),
    command(
        "02904 LockAxis(Phi(), Phi())",
        "LockAxis: PHI ARGUMENT USED TWICE",
    ),
    command(
        "02905 LockAxis(R(), R())",
        "LockAxis: R ARGUMENT USED TWICE",
    ),
    command(
        "02906 LockAxis(X(), X())",
        "LockAxis: X ARGUMENT USED TWICE",
    ),
    command(
        "02907 LockAxis(Y(), Y())",
        "LockAxis: Y ARGUMENT USED TWICE",
    ),
    command(
        "02908 LockAxis(Z(), Z())",
        "LockAxis: Z ARGUMENT USED TWICE",
    ),
    command("02909 LockAxis(Q())", "LockAxis: BAD ARGUMENTS"),
    command("E3001 OnMoveReportE(X)", "OnMoveReportE: BAD ARGUMENTS"),
    command("E3002 OnMoveReportE(X(2))", "OnMoveReportE: BAD ARGUMENTS"),
    command(
        "E3003 OnMoveReportE(R(), R())",
        "OnMoveReportE: R ARGUMENT USED TWICE",
    ),
    command(
        "E3004 OnMoveReportE(X(), X())",
        "OnMoveReportE: X ARGUMENT USED TWICE",
    ),
    command(
        "E3005 OnMoveReportE(Y(), Y())",
        "OnMoveReportE: Y ARGUMENT USED TWICE",
    ),
    command(
        "E3006 OnMoveReportE(Z(), Z())",
        "OnMoveReportE: Z ARGUMENT USED TWICE",
    ),
    command(
        "E3007 OnMoveReportE(Tool())",
        "OnMoveReportE: BAD ARGUMENTS",
    ),
    command(
        "E3008 OnMoveReportE(Tool.A(), Tool.A())",
        "OnMoveReportE: TOOL A ARGUMENT USED TWICE",
    ),
    command(
        "E3009 OnMoveReportE(Tool.B(), Tool.B())",
        "OnMoveReportE: TOOL B ARGUMENT USED TWICE",
    ),
    command(
        "E3010 OnMoveReportE(Tool.C(), Tool.C())",
        "OnMoveReportE: TOOL C ARGUMENT USED TWICE",
    ),
    command(
        "E3011 OnMoveReportE(Time(1), Dis(), X(), Y())",
        "OnMoveReportE: DIS MUST BE FOLLOWED BY NUMBER IN PARENS",
    ),
    command(
        "E3012 OnMoveReportE(Time(1), Dis(10), X(), Y(), Dis(8))",
        "OnMoveReportE: DIS ARGUMENT USED TWICE",
    ),
    command(
        "E3013 OnMoveReportE(Time(), Dis(10), X(), Y(), Z())",
        "OnMoveReportE: TIME MUST BE FOLLOWED BY NUMBER IN PARENS",
    ),
    command(
        "E3014 OnMoveReportE(Time(15), Time(3), Z())",
        "OnMoveReportE: TIME ARGUMENT USED TWICE",
    ),
    command("E3015 OnMoveReportE(Q())", "OnMoveReportE: BAD ARGUMENTS"),
    command("03101 OnPtMeasReport()", "OnPtMeasReport: BAD ARGUMENTS"),
    command(
        "03102 OnPtMeasReport(X(), Y)",
        "OnPtMeasReport: BAD ARGUMENTS",
    ),
    rejected(
        "03103 OnPtMeasReport(X(), Y,)",
        "OnPtMeasReport: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "03104 OnPtMeasReport(ER(), Z(), ER())",
        "OnPtMeasReport: ER ARGUMENT USED TWICE",
    ),
    command(
        "03105 OnPtMeasReport(IJK(), Z(), IJK())",
        "OnPtMeasReport: IJK ARGUMENT USED TWICE",
    ),
    command(
        "03106 OnPtMeasReport(R(), Z(), R())",
        "OnPtMeasReport: R ARGUMENT USED TWICE",
    ),
    command(
        "03107 OnPtMeasReport(X(), Z(), X())",
        "OnPtMeasReport: X ARGUMENT USED TWICE",
    ),
    command(
        "03108 OnPtMeasReport(Y(), Z(), Y())",
        "OnPtMeasReport: Y ARGUMENT USED TWICE",
    ),
    command(
        "03109 OnPtMeasReport(Y(), Z(), Z())",
        "OnPtMeasReport: Z ARGUMENT USED TWICE",
    ),
    command(
        "03110 OnPtMeasReport(Tool())",
        "OnPtMeasReport: BAD ARGUMENTS",
    ),
    command(
        "03111 OnPtMeasReport(Tool.A(), Tool.A())",
        "OnPtMeasReport: TOOL A ARGUMENT USED TWICE",
    ),
    command(
        "03112 OnPtMeasReport(Tool.B(), Tool.B())",
        "OnPtMeasReport: TOOL B ARGUMENT USED TWICE",
    ),
    command(
        "03113 OnPtMeasReport(Tool.C(), Tool.C())",
        "OnPtMeasReport: TOOL C ARGUMENT USED TWICE",
    ),
    command("03114 OnPtMeasReport(Q())", "OnPtMeasReport: BAD ARGUMENTS"),
    command("03201 OnScanReport()", "OnScanReport: BAD ARGUMENTS"),
    command("03202 OnScanReport(X(), Y)", "OnScanReport: BAD ARGUMENTS"),
    rejected(
        "03203 OnScanReport(X(), Y,)",
        "OnScanReport: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "03204 OnScanReport(ER(), Z(), ER())",
        "OnScanReport: ER ARGUMENT USED TWICE",
    ),
    command(
        "03205 OnScanReport(IJK(), Z(), IJK())",
        "OnScanReport: IJK ARGUMENT USED TWICE",
    ),
    command(
        "03206 OnScanReport(Q(), Z(), Q())",
        "OnScanReport: Q ARGUMENT USED TWICE",
    ),
    command(
        "03207 OnScanReport(R(), Z(), R())",
        "OnScanReport: R ARGUMENT USED TWICE",
    ),
    command(
        "03208 OnScanReport(X(), Z(), X())",
        "OnScanReport: X ARGUMENT USED TWICE",
    ),
    command(
        "03209 OnScanReport(Y(), Z(), Y())",
        "OnScanReport: Y ARGUMENT USED TWICE",
    ),
    command(
        "03210 OnScanReport(Y(), Z(), Z())",
        "OnScanReport: Z ARGUMENT USED TWICE",
    ),
    command("03211 OnScanReport(Tool())", "OnScanReport: BAD ARGUMENTS"),
    command(
        "03212 OnScanReport(Tool.A(), Tool.A())",
        "OnScanReport: TOOL A ARGUMENT USED TWICE",
    ),
    command(
        "03213 OnScanReport(Tool.B(), Tool.B())",
        "OnScanReport: TOOL B ARGUMENT USED TWICE",
    ),
    command(
        "03214 OnScanReport(Tool.C(), Tool.C())",
        "OnScanReport: TOOL C ARGUMENT USED TWICE",
    ),
    command("03215 OnScanReport(Dis())", "OnScanReport: BAD ARGUMENTS"),
    command("03301 PtMeas(X)", "PtMeas: BAD ARGUMENTS"),
    rejected("03302 PtMeas(X()2)", "PtMeas: BAD ARGUMENTS", "Expected"),
    command(
        "03303 PtMeas(X(), Y(2), Z(3))",
        "PtMeas: X NOT FOLLOWED BY NUMBER IN PARENS",
    ),
    command(
        "03304 PtMeas(X(1), X(2), Z(3))",
        "PtMeas: X ARGUMENT USED TWICE",
    ),
    command(
        "03305 PtMeas(X(2), Y(), Z(3))",
        "PtMeas: Y NOT FOLLOWED BY NUMBER IN PARENS",
    ),
    command(
        "03306 PtMeas(Y(1), Y(2), Z(3))",
        "PtMeas: Y ARGUMENT USED TWICE",
    ),
    command(
        "03307 PtMeas(X(2), Y(1), Z())",
        "PtMeas: Z NOT FOLLOWED BY NUMBER IN PARENS",
    ),
    command(
        "03308 PtMeas(Y(1), Z(2), Z(3))",
        "PtMeas: Z ARGUMENT USED TWICE",
    ),
    rejected(
        "03309 PtMeas(X(1), IJK,)",
        "PtMeas: IJK NOT FOLLOWED BY ARGIJK",
        "Expected",
    ),
    command(
        "03310 PtMeas(X(1), IJK(2,2,2), IJK(3,2,2))",
        "PtMeas: IJK ARGUMENT USED TWICE",
    ),
    command("03311 PtMeas(IJK(3,2,2))", "PtMeas: X Y Z ALL MISSING"),
    command("03401 ReQualify(1)", "ReQualify: MUST HAVE NO ARGUMENTS"),
    command(
        "03501 ScanInCylEndIsPlane(1)",
        "ScanInCylEndIsPlane: BAD ARGUMENTS",
    ),
    command(
        "03502 ScanInCylEndIsPlane(1,2,3,4,5,6,7,8,9,0,1,2,3,4,5,X,7,8,9,0,1,2,3,4,5,6)",
        "ScanInCylEndIsPlane: BAD ARGUMENTS",
    ),
    command(
        "03503 ScanInCylEndIsPlane(1,2,3,4,5,6,7,8,9,0,1,2,3,4,5,-6,7,8,9,0,1,2,3,4,5,6)",
        "ScanInCylEndIsPlane: STEPW MUST BE POSITIVE",
    ),
    command(
        "03504 ScanInCylEndIsPlane(1,2,3,4,5,6,7,8,9,0,1,2,3,4,5,6,7,8,9,0,1,2,-3,4,5,6)",
        "ScanInCylEndIsPlane: NUMBER THROUGH MUST BE POSITIVE",
    ),
    command(
        "03505 ScanInCylEndIsPlane(1,2,3,4,5,6,7,8,9,0,1,2,3,4,5,6,7,8,9,0,1,2,3.1,4,5,6)",
        "ScanInCylEndIsPlane: NUMBER THROUGH MUST BE INTEGER",
    ),
    command(
        "03506 ScanInCylEndIsPlane(X,2,3,4,5,6,7,8,9,0,1,2,3,4,5,6,7,8,9,0,1,2,3,4,5,6)",
        "ScanInCylEndIsPlane: BAD ARGUMENTS",
    ),
    command(
        "03601 ScanInCylEndIsSphere(1)",
        "ScanInCylEndIsSphere: BAD ARGUMENTS",
    ),
    command(
        "03602 ScanInCylEndIsSphere(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,X,7,8,9,10,1,2,3)",
        "ScanInCylEndIsSphere: BAD ARGUMENTS",
    ),
    command(
        "03603 ScanInCylEndIsSphere(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,-6,7,8,9,10,1,2,3)",
        "ScanInCylEndIsSphere: STEPW MUST BE POSITIVE",
    ),
    command(
        "03604 ScanInCylEndIsSphere(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,7,8,9,-10,1,2,3)",
        "ScanInCylEndIsSphere: DIAMETER MUST BE POSITIVE",
    ),
    command(
        "03605 ScanInCylEndIsSphere(X,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,7,8,9,10,1,2,3)",
        "ScanInCylEndIsSphere: BAD ARGUMENTS",
    ),
    command(
        "03701 ScanInPlaneEndIsCyl(1)",
        "ScanInPlaneEndIsCyl: BAD ARGUMENTS",
    ),
    command(
        "03702 ScanInPlaneEndIsCyl(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,X,8,9,10,1)",
        "ScanInPlaneEndIsCyl: BAD ARGUMENTS",
    ),
    command(
        "03703 ScanInPlaneEndIsCyl(1,2,3,4,5,6,7,8,9,-10,1,2,3,4,5,6,7,8,9,10,1)",
        "ScanInPlaneEndIsCyl: STEPW MUST BE POSITIVE",
    ),
    command(
        "03704 ScanInPlaneEndIsCyl(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,-7,8,9,10,1)",
        "ScanInPlaneEndIsCyl: DIAMETER MUST BE POSITIVE",
    ),
    command(
        "03705 ScanInPlaneEndIsCyl(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,7,-8,9,10,1)",
        "ScanInPlaneEndIsCyl: NUMBER THROUGH MUST BE POSITIVE",
    ),
    command(
        "03706 ScanInPlaneEndIsCyl(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,7,8.1,9,10,1)",
        "ScanInPlaneEndIsCyl: NUMBER THROUGH MUST BE INTEGER",
    ),
    command(
        "03707 ScanInPlaneEndIsCyl(X,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,7,8,9,10,1)",
        "ScanInPlaneEndIsCyl: BAD ARGUMENTS",
    ),
    command(
        "03801 ScanInPlaneEndIsPlane(1)",
        "ScanInPlaneEndIsPlane: BAD ARGUMENTS",
    ),
    command(
        "03802 ScanInPlaneEndIsPlane(1,2,3,4,5,6,7,8,9,X,1,2,3,4,5,6,7,8,9,10)",
        "ScanInPlaneEndIsPlane: BAD ARGUMENTS",
    ),
    command(
        "03803 ScanInPlaneEndIsPlane(1,2,3,4,5,6,7,8,9,-10,1,2,3,4,5,6,7,8,9,10)",
        "ScanInPlaneEndIsPlane: STEPW MUST BE POSITIVE",
    ),
    command(
        "03804 ScanInPlaneEndIsPlane(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,-7,8,9,10)",
        "ScanInPlaneEndIsPlane: NUMBER THROUGH MUST BE POSITIVE",
    ),
    command(
        "03805 ScanInPlaneEndIsPlane(1,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,7.1,8,9,10)",
        "ScanInPlaneEndIsPlane: NUMBER THROUGH MUST BE INTEGER",
    ),
    command(
        "03806 ScanInPlaneEndIsPlane(X,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,7,8,9,10)",
        "ScanInPlaneEndIsPlane: BAD ARGUMENTS",
    ),
    command(
        "03901 ScanInPlaneEndIsSphere(1)",
        "ScanInPlaneEndIsSphere: BAD ARGUMENTS",
    ),
    command(
        "03902 ScanInPlaneEndIsSphere(1,2,3,4,5,6,7,8,9,X,1,2,3,4,5,6,7)",
        "ScanInPlaneEndIsSphere: BAD ARGUMENTS",
    ),
    command(
        "03903 ScanInPlaneEndIsSphere(1,2,3,4,5,6,7,8,9,-10,1,2,3,4,5,6,7)",
        "ScanInPlaneEndIsSphere: STEPW MUST BE POSITIVE",
    ),
    command(
        "03904 ScanInPlaneEndIsSphere(1,2,3,4,5,6,7,8,9,10,1,2,3,-4,5,6,7)",
        "ScanInPlaneEndIsSphere: DIAMETER MUST BE POSITIVE",
    ),
    command(
        "03905 ScanInPlaneEndIsSphere(X,2,3,4,5,6,7,8,9,10,1,2,3,4,5,6,7)",
        "ScanInPlaneEndIsSphere: BAD ARGUMENTS",
    ),
    command("04001 ScanOnCircle(1)", "ScanOnCircle: BAD ARGUMENTS"),
    command(
        "04002 ScanOnCircle(1,2,3,4,5,6,7,8,9,10,1,X)",
        "ScanOnCircle: BAD ARGUMENTS",
    ),
    command(
        "04003 ScanOnCircle(X,2,3,4,5,6,7,8,9,10,1,2)",
        "ScanOnCircle: BAD ARGUMENTS",
    ),
    command(
        "04101 ScanOnCircleHint(1)",
        "ScanOnCircleHint: BAD ARGUMENTS",
    ),
    command("04201 ScanOnLine(1)", "ScanOnLine: BAD ARGUMENTS"),
    command(
        "04202 ScanOnLine(1,2,3,4,5,6,7,8,9,X)",
        "ScanOnLine: BAD ARGUMENTS",
    ),
    command(
        "04203 ScanOnLine(1,2,3,4,5,6,7,8,9,-10)",
        "ScanOnLine: STEPW MUST BE POSITIVE",
    ),
    command(
        "04204 ScanOnLine(X,2,3,4,5,6,7,8,9,10)",
        "ScanOnLine: BAD ARGUMENTS",
    ),
    command("04301 ScanOnLineHint(1)", "ScanOnLineHint: BAD ARGUMENTS"),
    command(
        "04401 ScanUnknownHint()",
        "ScanUnknownHint: MUST HAVE ONE ARGUMENT",
    ),
    command(
        r#"04402 ScanUnknownHint("bigger than a breadbox")"#,
        "ScanUnknownHint: ARGUMENT MUST BE A NUMBER",
    ),
    command(
        "04403 ScanUnknownHint(-1)",
        "ScanUnknownHint: ARGUMENT MUST BE POSITIVE",
    ),
    command(
        "04501 SetCoordSystem(MachineCsy, PartCsy)",
        "SetCoordSystem: MUST HAVE ONE ARGUMENT",
    ),
    command(
        "04502 SetCoordSystem(JogMoveCsy)",
        "SetCoordSystem: BAD ARGUMENTS",
    ),
    command(
        "04601 SetCsyTransformation(PartCsy)",
        "SetCsyTransformation: MUST HAVE 7 ARGUMENTS",
    ),
    command(
        "04602 SetCsyTransformation(1, 1, 1, 1, 180, 180, 180)",
        "SetCsyTransformation: BAD ARGUMENTS",
    ),
    command(
        "04603 SetCsyTransformation(X, 1, 1, 1, 180, 180, 180)",
        "SetCsyTransformation: BAD FIRST ARGUMENT",
    ),
    command(
        "04604 SetCsyTransformation(PartCsy, 1, 1, 1, 200, 180, 180)",
        "SetCsyTransformation: THETA OUT OF RANGE",
    ),
    command(
        "04701 SetProp(Tool.PtMeasPar(54))",
        "SetProp: BAD ARGUMENTS",
    ),
    command(
        "04702 SetProp(X.PtMeasPar.Accel(3))",
        "SetProp: ARGUMENT FIRST PART MUST BE TOOL OR FOUNDTOOL",
    ),
    command(
        "04703 SetProp(FoundTool,PtMeasPar,Speed(25.0))",
        "SetProp: BAD DOTS",
    ),
    command(
        "04704 SetProp(FoundTool.Accel.Accel(2))",
        "SetProp: ARGUMENT SECOND PART MUST BE GOTOPAR OR PTMEASPAR",
    ),
    command(
        "04705 SetProp(FoundTool.PtMeasPar.Dis(1))",
        "SetProp: ARGUMENT THIRD PART BAD",
    ),
    command(
        "04706 SetProp(FoundTool.PtMeasPar.Accel())",
        "SetProp: BAD DOTS",
    ),
    rejected(
        "04707 SetProp(FoundTool.PtMeasPar.Accel.Max)",
        "SetProp: BAD ARGUMENTS",
        "Expected",
    ),
    command(
        "04708 SetProp(FoundTool.PtMeasPar.Accel.Max(3))",
        "SetProp: ARGUMENT FOURTH PART MUST BE ACT",
    ),
    command(
        "04709 SetProp(FoundTool.PtMeasPar.Accel.Act())",
        "SetProp: ARGUMENT MUST END WITH NUMBER IN PARENTHESES",
    ),
    rejected(
        "04710 SetProp(FoundTool.PtMeasPar.Accel.Act(4)(4))",
        "SetProp: BAD ARGUMENTS",
        "Expected",
    ),
    command("04801 SetTool()", "SetTool: MUST HAVE ONE ARGUMENT"),
    command("04802 SetTool(2)", "SetTool: ARGUMENT MUST BE STRING"),
    command(
        "04901 StartSession(1)",
        "StartSession: MUST HAVE NO ARGUMENTS",
    ),
    command(
        "05001 StopAllDaemons(1)",
        "StopAllDaemons: MUST HAVE NO ARGUMENTS",
    ),
    command("05101 StopDaemon()", "StopDaemon: MUST HAVE ONE ARGUMENT"),
    command(
        "05102 StopDaemon(05101)",
        "StopDaemon: ARGUMENT MUST BE EVENT TAG",
    ),
    command(
        "05201 TiltCenterPart()",
        "TiltCenterPart: MUST HAVE 7 ARGUMENTS",
    ),
    command(
        "05202 TiltCenterPart(X,2,3,4,5,6,7)",
        "TiltCenterPart: BAD ARGUMENTS",
    ),
    command("05301 TiltPart()", "TiltPart: MUST HAVE 4 ARGUMENTS"),
    command("05302 TiltPart(X,2,3,4)", "TiltPart: BAD ARGUMENTS"),
    rejected(
        "05400 Errors from parseCommand",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    rejected(
        "05401 GoTo(X(0.1))2",
        "GoTo: BAD CHARACTER AFTER COMMAND END",
        "UnterminatedLine",
    ),
    rejected(
        "05402 AbortE()",
        "AbortE: EVENT COMMAND MUST HAVE EVENT TAG",
        "FastCommandWithoutEventTag",
    ),
    rejected(
        "E5403 GoTo(X(0.1))",
        "GoTo: NON EVENT COMMAND MUST NOT HAVE EVENT TAG",
        "EventTagOnNormalCommand",
    ),
    rejected(
        "05500 Errors from parseCmdArguments",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    rejected(
        "05501 GoTo(X(1,)",
        "GoTo: BAD COMMAND ARGUMENTS",
        "Expected",
    ),
    rejected(
        "05502 GoTo(X(#))",
        "GoTo: BAD COMMAND ARGUMENTS",
        "Expected",
    ),
    rejected(
        "05600 Errors from parseCmdName",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    command("05601 CmdName()", "BAD COMMAND NAME"),
    rejected(
        "05700 Errors from parseKeyword",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    command("05701 GoTo(X2)", "GoTo: BAD CHARACTER AFTER KEYWORD"),
    command("05702 GoTo(Keyword)", "GoTo: BAD KEYWORD"),
    rejected(
        "05800 Errors from parseNumber",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    rejected(
        "05801 GoTo(X(+1.1.2))",
        "GoTo: BAD NUMBER TWO DECIMAL POINTS",
        "NumberTwoDecimalPoints",
    ),
    rejected(
        "05802 GoTo(X(+.))",
        "GoTo: BAD NUMBER NO DIGITS",
        "NumberWithoutDigits",
    ),
    rejected(
        "05803 GoTo(X(12345671901234567))",
        "GoTo: BAD NUMBER MORE THAN 16 DIGITS",
        "NumberTooManyDigits",
    ),
    rejected(
        "05804 GoTo(X(2.1E0001))",
        "GoTo: BAD E NUMBER EXPONENT MUST HAVE ONE TWO OR THREE DIGITS",
        "NumberBadExponent",
    ),
    rejected(
        "05900 Errors from parseString",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    rejected(r#"05901 GoTo("hello)"#, "GoTo: BAD STRING", "BadString"),
    rejected(r#"05902 GoTo("")"#, "GoTo: BAD STRING", "BadString"),
    rejected(
        "06000 Errors from parseTag",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    rejected("A2345 GoTo(X(3.1))", "BAD TAG CHARACTER", "BadTag"),
    rejected(
        "012345 GoTo(X(3.1))",
        "SPACE MISSING AFTER TAG",
        "MissingSpaceAfterTag",
    ),
    rejected(
        "E0000 AbortE()",
        "TAG NUMBER OUT OF RANGE FOR EVENT TAG",
        "UnsolicitedTagInCommand",
    ),
    rejected(
        "00000 GoTo(X(2.1))",
        "TAG NUMBER OUT OF RANGE FOR COMMAND TAG",
        "TagOutOfRange",
    ),
    rejected(
        "06100 Errors from parseIJK",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    rejected(
        "06101 GoTo(IJK(1+2+3))",
        "GoTo: BAD IJK NUMBERS",
        "Expected",
    ),
    command("06102 GoTo(IJK(2,A))", "GoTo: BAD IJK NUMBERS"),
    command("06103 GoTo(IJK(1,2,3,4))", "GoTo: BAD IJK NUMBERS"),
    rejected(
        "06200 Errors from unSpaceInputArray",
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
    rejected("06201 GoTo(X(2.1 E2))", "ILLEGAL SPACE", "IllegalSpace"),
];

/// parserResErrors.txt: "The parserResErrors.res file is designed to trigger all the source lines of the
/// form "errorCode = XXX;" [of] parserRes.cc": every line.
const PARSER_RES_ERRORS: &[MeantToFail] = &[
    rejected(
        r#"00101 # ("start error messages from makeAlignResponse")"#,
        "AlignResponse: BAD RESPONSE ITEMS",
        "NumberWithoutDigits",
    ),
    command(
        r#"00201 # CenterPart("start error messages from makeCenterPartResponse")"#,
        "CenterPartResponse: BAD RESPONSE ITEMS",
    ),
    command(
        "00202 # CenterPart(3)",
        "CenterPartResponse: VALUE MUST BE 0 OR 1",
    ),
    rejected(
        r#"E0000 # ChangeTool("start error messages from makeChangeToolEResponse"("#,
        "ChangeToolEResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"00401 # ) "start error messages from makeDataResponse""#,
        "BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"00501 # "start error messages from makeEnumPropResponse", 30"#,
        "EnumPropResponse: BAD RESPONSE ITEMS",
        "MixedData",
    ),
    rejected(
        r#"00601 ! Error(1, 0512, "start error messages from makeErrorResponse")"#,
        "ErrorResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"00602 ! Tool(1, 0512, "me", "No daemons are active")"#,
        "ErrorResponse: RESPONSE NAME MUST BE ERROR",
        "NotAnErrorCall",
    ),
    rejected(
        r#"00603 ! Error(01, 0512, "me", "No daemons are active")"#,
        "ErrorResponse: SEVERITY MUST HAVE ONE DIGIT",
        "SeverityNotOneDigit",
    ),
    rejected(
        r#"00604 ! Error(1, 512, "me", "No daemons are active")"#,
        "ErrorResponse: ERROR CODE MUST HAVE FOUR DIGITS",
        "CodeNotFourDigits",
    ),
    command(
        r#"00605 ! Error(1, 8888, "oops", "text")"#,
        "ErrorResponse: BAD ERROR CODE",
    ),
    command(
        r#"00606 ! Error(1, 0512, "me", "No deamons are active")"#,
        "ErrorResponse: BAD TEXT",
    ),
    command(
        r#"00607 ! Error(2, 0512, "me", "No daemons are active")"#,
        "ErrorResponse: BAD SEVERITY",
    ),
    command(
        r#"00701 # ChangeToolAction("error messages makeGetChangeToolActionResponse")"#,
        "ChangeToolActionResponse: BAD RESPONSE ITEMS",
    ),
    command(
        "00702 # ChangeToolAction(Tool, X(0), Y(0), Z(0))",
        "ChangeToolActionResponse: FIRST ARGUMENT MUST BE SWITCH ROTATE MOVEAUTO OR MOVEMAN",
    ),
    command(
        r#"00801 # CoordSystem("start error messages from makeGetCoordSystemResponse")"#,
        "GetCoordSystemResponse: BAD RESPONSE ITEMS",
    ),
    command(
        "00802 # CoordSystem(X)",
        "GetCoordSystemResponse: BAD COORDINATE SYSTEM",
    ),
    command(
        r#"00901 # GetCsyTransformation("err messages makeGetCsyTransformationResponse")"#,
        "GetCsyTransformationResponse: BAD RESPONSE ITEMS",
    ),
    rejected(
        r#"01001 # DMEVersion("start error messages from makeGetDMEVersionResponse""#,
        "GetDMEVersionResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"01101 # ErrStatus("start error messages from makeGetErrStatusEResponse""#,
        "GetErrStatusEResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "01102 # ErrStatus(2)",
        "GetErrStatusEResponse: VALUE MUST BE 0 OR 1",
    ),
    rejected(
        r#"01201 # GetMachineClass("start error messages makeGetMachineClassResponse""#,
        "GetMachineClassResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        r#"01202 # GetMachineClass("HorseCMM")"#,
        "GetMachineClassResponse: BAD MACHINE CLASS",
    ),
    rejected(
        r#"01301 # Tool.GoToPar,"start error messages from makeGetPropResponse""#,
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "01302 # FoundTool.Alignment(0)",
        "GetPropResponse: BAD SECOND KEYWORD",
    ),
    command(
        "01303 # FoundTool.CollisionVolume(0)",
        "GetPropResponse: BAD SECOND KEYWORD",
    ),
    command(
        "01304 # FoundTool.X(0)",
        "GetPropResponse: BAD SECOND KEYWORD",
    ),
    rejected(
        r#"E0000 # GoTo)"start error messages from makeGoToEResponse""#,
        "GoToEResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command("E0000 # GoTo(1)", "GoToEResponse: BAD RESPONSE ITEMS"),
    command(
        r#"E0000 # GoTo(X("One"))"#,
        "GoToEResponse: BAD RESPONSE ITEMS",
    ),
    command("E0000 # GoTo(ER(1), ER(2))", "GoToEResponse: ER USED TWICE"),
    command("E0000 # GoTo(R(1), R(2))", "GoToEResponse: R USED TWICE"),
    command("E0000 # GoTo(X(1), X(2))", "GoToEResponse: X USED TWICE"),
    command("E0000 # GoTo(Y(1), Y(2))", "GoToEResponse: Y USED TWICE"),
    command("E0000 # GoTo(Z(1), Z(2))", "GoToEResponse: Z USED TWICE"),
    rejected(
        "E0000 # GoTo(Tool(X(3))",
        "GoToEResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "E0000 # GoTo(Tool.A(1), Tool.A(2))",
        "GoToEResponse: TOOL A USED TWICE",
    ),
    command(
        "E0000 # GoTo(Tool.B(1), Tool.B(2))",
        "GoToEResponse: TOOL B USED TWICE",
    ),
    command(
        "E0000 # GoTo(Tool.C(1), Tool.C(2))",
        "GoToEResponse: TOOL C USED TWICE",
    ),
    command("E0000 # GoTo(IJK(1))", "GoToEResponse: BAD RESPONSE ITEMS"),
    command(
        "E0000 # GoTo(IJK(0, 0, 0), IJK(0, 0, 0))",
        "GoToEResponse: IJK USED TWICE",
    ),
    command(
        "E0000 # GoTo(IJK(1, 0, 0))",
        "GoToEResponse: IJK VALUES MUST BE ZERO",
    ),
    command("E0000 # GoTo(Q(1))", "GoToEResponse: BAD RESPONSE ITEMS"),
    command(
        r#"01501 # IsHomed(0, "start error messages from makeIsHomedResponse")"#,
        "IsHomedResponse: BAD RESPONSE ITEMS",
    ),
    command(
        "01502 # IsHomed(4)",
        "IsHomedResponse: VALUE MUST BE 0 OR 1",
    ),
    command(
        r#"01601 # IsUserEnabled("start error messages from makeIsUserEnabledResponse")"#,
        "IsUserEnabledResponse: BAD RESPONSE ITEMS",
    ),
    command(
        "01602 # IsUserEnabled(5)",
        "IsUserEnabledResponse: VALUE MUST BE 0 OR 1",
    ),
    command(
        r#"E0000 # KeyPress(1, "start error messages from makeKeyPressEResponse")"#,
        "KeyPressEResponse: BAD RESPONSE ITEMS",
    ),
    command(
        r#"01801 # Tool.Alignment("start error messages from makeOnePropertyAlignment")"#,
        "GetPropResponse: BAD RESPONSE ITEMS",
    ),
    rejected(
        "01802 # Tool.Alignment(1,2,3(",
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        "01803 # Tool.Alignment(1,2,3,4,5,6(",
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        "01804 # Tool.Alignment(1,2,3,4",
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"01901 # Tool.CollisionVolume),"error messages makeOnePropertyCollisionVolume""#,
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "01902 # Tool.CollisionVolume(1)",
        "GetPropResponse: BAD RESPONSE ITEMS",
    ),
    rejected(
        "01903 # Tool.CollisionVolume(OBB,,,10,530,50,50,50,1,0,0,0,1,0,0,0,1)",
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        "01904 # Tool.CollisionVolume(OBB,150,10,530,50,50,50,1,0,0,0,1,0,0,0,1OBB(",
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        "01905 # Tool.CollisionVolume(OBB,150,10,530,50,50,50,1,0,0,0,1,0,0,0,1))",
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"02001 # Tool.Id() "start error messages from makeOnePropertyId""#,
        "GetPropResponse: BAD RESPONSE ITEMS",
        "IllegalSpace",
    ),
    rejected(
        r#"02101 # Tool.Name() "start error messages from makeOnePropertyName""#,
        "GetPropResponse: BAD RESPONSE ITEMS",
        "IllegalSpace",
    ),
    rejected(
        r#"02201 # Tool.GoToPar,Speed("start error messages from makeOnePropertyNumber")"#,
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "02202 # Tool.GoToPar.Speed.X(3)",
        "GetPropResponse: BAD RESPONSE ITEMS",
    ),
    command(
        r#"02203 # Tool.GoToPar.Speed("3")"#,
        "GetPropResponse: BAD RESPONSE ITEMS",
    ),
    rejected(
        "02204 # Tool.GoToPar.Speed,(3)",
        "GetPropResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "02205 # Tool.GoToPar.Retract(3)",
        "GetPropResponse: BAD GOTOPAR PROPERTY",
    ),
    command(
        "02206 # Tool.PtMeasPar.Max(3)",
        "GetPropResponse: BAD PTMEASPAR PROPERTY",
    ),
    rejected(
        r#"E0000 # PtMeas) "start error messages from makePtMeasEResponse""#,
        "PtMeasEResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command("E0000 # PtMeas(3)", "PtMeasEResponse: BAD RESPONSE ITEMS"),
    rejected(
        "E0000 # PtMeas(X(3()",
        "PtMeasEResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "E0000 # PtMeas(ER(1), ER(2))",
        "PtMeasEResponse: ER USED TWICE",
    ),
    command(
        "E0000 # PtMeas(R(1), R(2))",
        "PtMeasEResponse: R USED TWICE",
    ),
    command(
        "E0000 # PtMeas(X(1), X(2))",
        "PtMeasEResponse: X USED TWICE",
    ),
    command(
        "E0000 # PtMeas(Y(1), Y(2))",
        "PtMeasEResponse: Y USED TWICE",
    ),
    command(
        "E0000 # PtMeas(Z(1), Z(2))",
        "PtMeasEResponse: Z USED TWICE",
    ),
    command(
        "E0000 # PtMeas(Tool(3))",
        "PtMeasEResponse: BAD RESPONSE ITEMS",
    ),
    command(
        "E0000 # PtMeas(Tool.A(1), Tool.A(2))",
        "PtMeasEResponse: TOOL A USED TWICE",
    ),
    command(
        "E0000 # PtMeas(Tool.B(1), Tool.B(2))",
        "PtMeasEResponse: TOOL B USED TWICE",
    ),
    command(
        "E0000 # PtMeas(Tool.C(1), Tool.C(2))",
        "PtMeasEResponse: TOOL C USED TWICE",
    ),
    command(
        "E0000 # PtMeas(IJK(3))",
        "PtMeasEResponse: BAD RESPONSE ITEMS",
    ),
    command(
        "E0000 # PtMeas(IJK(0,0,1), IJK(0,0,1))",
        "PtMeasEResponse: IJK USED TWICE",
    ),
    command(
        "E0000 # PtMeas(Max(3))",
        "PtMeasEResponse: BAD RESPONSE ITEMS",
    ),
    rejected(
        r#"02301 # X("start error messages from makePtMeasOrGetResponse""#,
        "PtMeasOrGetResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        r#"02302 # X("oops")"#,
        "PtMeasOrGetResponse: BAD RESPONSE ITEMS",
    ),
    command("02303 # ER(3), ER(3)", "PtMeasOrGetResponse: ER USED TWICE"),
    command("02304 # R(3), R(3)", "PtMeasOrGetResponse: R USED TWICE"),
    command("02305 # X(3), X(3)", "PtMeasOrGetResponse: X USED TWICE"),
    command("02306 # Y(3), Y(3)", "PtMeasOrGetResponse: Y USED TWICE"),
    command("02307 # Z(3), Z(3)", "PtMeasOrGetResponse: Z USED TWICE"),
    rejected(
        "02308 # Tool,A(3)",
        "PtMeasOrGetResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "02309 # Tool.A(3), Tool.A(3)",
        "PtMeasOrGetResponse: TOOL A USED TWICE",
    ),
    command(
        "02310 # Tool.B(3), Tool.B(3)",
        "PtMeasOrGetResponse: TOOL B USED TWICE",
    ),
    command(
        "02311 # Tool.C(3), Tool.C(3)",
        "PtMeasOrGetResponse: TOOL C USED TWICE",
    ),
    command("02312 # IJK(3)", "PtMeasOrGetResponse: BAD RESPONSE ITEMS"),
    command(
        "02313 # IJK(0,0,1), IJK(0,0,1)",
        "PtMeasOrGetResponse: IJK USED TWICE",
    ),
    command(
        "02314 # X(3), Q(4)",
        "PtMeasOrGetResponse: BAD RESPONSE ITEMS",
    ),
    rejected(
        r#"02401 # 3,,"start error messages from makeScanResponse""#,
        "ScanResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        "02402 # 3,,3,",
        "ScanResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        "02403 # 3)3",
        "ScanResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"E0000 # X("start error messages from makeServerInitiatedResponse""#,
        "BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"E0000 # SetProp("start error messages from makeSetPropEResponse""#,
        "SetPropEResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "E0000 # SetProp(Tool.GoToPar.X(3))",
        "SetPropEResponse: BAD KEYWORD",
    ),
    command(
        r#"E0000 # SetProp(Tool.GoToPar.Speed("2"))"#,
        "SetPropEResponse: BAD RESPONSE ITEMS",
    ),
    command(
        r#"E0000 # SetProp(Tool.GoToPar.Speed.Act("2"))"#,
        "SetPropEResponse: BAD RESPONSE ITEMS",
    ),
    command(
        "E0000 # SetProp(Tool.GoToPar.Speed.Max(2))",
        "SetPropEResponse: BAD KEYWORD",
    ),
    rejected(
        "E0000 # SetProp(Tool.GoToPar.Speed.Act(2)",
        "SetPropEResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        r#"02601 # TiltCenterPart("start error messages from makeTiltCenterPartResponse""#,
        "TiltCenterPartResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "02602 # TiltCenterPart(2)",
        "TiltCenterPartResponse: VALUE MUST BE 0 OR 1",
    ),
    rejected(
        r#"02701 # TiltPart("start error messages from makeTiltPartResponse""#,
        "TiltPartResponse: BAD RESPONSE ITEMS",
        "Expected",
    ),
    command(
        "02702 # TiltPart(2)",
        "TiltPartResponse: VALUE MUST BE 0 OR 1",
    ),
    command(
        r#"02801 # Isomed("start error messages from parseKeyword")"#,
        "BAD KEYWORD",
    ),
    rejected(
        "02802 # IsHomedic",
        "BAD CHARACTER AFTER KEYWORD",
        "Expected",
    ),
    rejected(
        r#"02901 # X(1.2.3("start error messages from parseNumber"))"#,
        "BAD NUMBER TWO DECIMAL POINTS",
        "NumberTwoDecimalPoints",
    ),
    rejected(
        "02902 # X(+)",
        "BAD NUMBER NO DIGITS",
        "NumberWithoutDigits",
    ),
    rejected(
        "02903 # X(12345678901234567)",
        "BAD NUMBER MORE THAN 16 DIGITS",
        "NumberTooManyDigits",
    ),
    rejected(
        "02904 # X(17.2E1234)",
        "BAD E NUMBER EXPONENT MUST HAVE ONE TWO OR THREE DIGITS",
        "NumberBadExponent",
    ),
    rejected(
        r#"03001 # s"start error messages from parseResItems""#,
        "BAD RESPONSE ITEMS",
        "Expected",
    ),
    rejected(
        "03101 &start error messages from parseResponse",
        "BAD CHARACTER AFTER RESPONSE END",
        "TrailingCharacters",
    ),
    rejected(
        "03102 %oops",
        "BAD CHARACTER AFTER RESPONSE END",
        "TrailingCharacters",
    ),
    rejected(
        "03103 $ X(3)",
        "BAD SEVENTH CHARACTER IN RESPONSE",
        "BadMarker",
    ),
    rejected(
        "03104 #X(3)",
        "SPACE MISSING AT EIGHTH CHARACTER OF RESPONSE",
        "MissingSpaceAfterMarker",
    ),
    rejected(
        "03105 # IsHomed(0)",
        "BAD CHARACTER AFTER RESPONSE END",
        "BadTag",
    ),
    rejected(
        r#"03201 # "start error messages"#,
        "BAD STRING",
        "IllegalCharacter",
    ),
    rejected(
        r#"033A1 # "start error messages from parseTag""#,
        "BAD TAG CHARACTER",
        "BadTag",
    ),
    rejected(
        "03302# X(3)",
        "SPACE MISSING AFTER TAG",
        "MissingSpaceAfterTag",
    ),
    rejected(
        "E0000 &",
        "ZERO TAG MUST BE SERVER INITIATED RESPONSE",
        "UnsolicitedTagOnTransaction",
    ),
    rejected("A3304 # X(2)", "BAD TAG CHARACTER", "BadTag"),
    rejected(
        r#"03401 # Tool. GoToPars("start error messages from unSpaceInputArray")"#,
        "ILLEGAL SPACE",
        "IllegalSpace",
    ),
];

/// numbersErrorCmd.txt: "The numbersErrorCmd.prg file contains commands that have number errors", listed
/// with the parser's messages; its other commands (StartSession, EndSession, ClearAllErrors) are valid.
const NUMBERS_ERROR_CMD: &[MeantToFail] = &[
    rejected(
        "00010 GoTo(X(12345678901234567))",
        "BAD NUMBER MORE THAN 16 DIGITS",
        "NumberTooManyDigits",
    ),
    rejected(
        "00020 GoTo(X(-.))",
        "BAD NUMBER NO DIGITS",
        "NumberWithoutDigits",
    ),
    rejected(
        "00030 GoTo(X(+))",
        "BAD NUMBER NO DIGITS",
        "NumberWithoutDigits",
    ),
    rejected("00040 GoTo(X(+1.2 E2))", "ILLEGAL SPACE", "IllegalSpace"),
    rejected(
        "00050 GoTo(X(+1.2E))",
        "BAD E NUMBER EXPONENT MUST HAVE ONE TWO OR THREE DIGITS",
        "NumberBadExponent",
    ),
    rejected(
        "00060 GoTo(X(+1.2E0010))",
        "BAD E NUMBER EXPONENT MUST HAVE ONE TWO OR THREE DIGITS",
        "NumberBadExponent",
    ),
    rejected(
        "00070 GoTo(X(0.34.33))",
        "BAD NUMBER TWO DECIMAL POINTS",
        "NumberTwoDecimalPoints",
    ),
];

/// numbersErrorRes.txt: the response parser's message for each line; every line fails.
const NUMBERS_ERROR_RES: &[MeantToFail] = &[
    rejected(
        "E0000 # GoTo(X(12345678901234567))",
        "BAD NUMBER MORE THAN 16 DIGITS",
        "NumberTooManyDigits",
    ),
    rejected(
        "E0000 # GoTo(X(-.))",
        "BAD NUMBER NO DIGITS",
        "NumberWithoutDigits",
    ),
    rejected(
        "E0000 # GoTo(X(+))",
        "BAD NUMBER NO DIGITS",
        "NumberWithoutDigits",
    ),
    rejected("E0000 # GoTo(X(+1.2 E2))", "ILLEGAL SPACE", "IllegalSpace"),
    rejected(
        "E0000 # GoTo(X(+1.2E))",
        "BAD E NUMBER EXPONENT MUST HAVE ONE TWO OR THREE DIGITS",
        "NumberBadExponent",
    ),
    rejected(
        "E0000 # GoTo(X(+1.2E0010))",
        "BAD E NUMBER EXPONENT MUST HAVE ONE TWO OR THREE DIGITS",
        "NumberBadExponent",
    ),
    rejected(
        "E0000 # GoTo(X(0.34.33))",
        "BAD NUMBER TWO DECIMAL POINTS",
        "NumberTwoDecimalPoints",
    ),
];

/// checkerCmdErrors.txt: "The checkerCmdErrors.prg file passes through the command parser without error,
/// except for one instance of THETA_OUT_OF_RANGE." Its other errors (not homed, undefined tool, ...) depend
/// on the machine's state, not on the line.
const CHECKER_CMD_ERRORS: &[MeantToFail] = &[command(
    "04601 SetCsyTransformation(PartCsy, 0, 0, 0, 180.1, 0, 0)",
    "SetCsyTransformation: THETA OUT OF RANGE",
)];
