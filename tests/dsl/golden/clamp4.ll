define <4 x float> @"clamp4"(<4 x float> %"v", float %"lo") nounwind
{
entry:
  br label %"body"
body:
  %"lo.splat" = insertelement <4 x float> <float undef, float undef, float undef, float undef>, float %"lo", i32 0
  %"lo.splat.1" = shufflevector <4 x float> %"lo.splat", <4 x float> <float undef, float undef, float undef, float undef>, <4 x i32> <i32 0, i32 0, i32 0, i32 0>
  %"gt" = fcmp ogt <4 x float> %"v", %"lo.splat.1"
  %"max" = select  <4 x i1> %"gt", <4 x float> %"v", <4 x float> %"lo.splat.1"
  %"lt" = fcmp olt <4 x float> %"max", <float 0x3ff0000000000000, float 0x3ff0000000000000, float 0x3ff0000000000000, float 0x3ff0000000000000>
  %"min" = select  <4 x i1> %"lt", <4 x float> %"max", <4 x float> <float 0x3ff0000000000000, float 0x3ff0000000000000, float 0x3ff0000000000000, float 0x3ff0000000000000>
  %"ne" = fcmp une <4 x float> %"v", %"v"
  %"select" = select  <4 x i1> %"ne", <4 x float> <float              0x0, float              0x0, float              0x0, float              0x0>, <4 x float> %"min"
  ret <4 x float> %"select"
}

define void @"clamp4.entry"(i8** %"argv", i8* %"ret") nounwind
{
entry:
  br label %"body"
body:
  %"v.argv" = getelementptr inbounds i8*, i8** %"argv", i64 0
  %"v.arg" = load i8*, i8** %"v.argv"
  %"v.p" = bitcast i8* %"v.arg" to <4 x float>*
  %"v" = load <4 x float>, <4 x float>* %"v.p", align 4
  %"lo.argv" = getelementptr inbounds i8*, i8** %"argv", i64 1
  %"lo.arg" = load i8*, i8** %"lo.argv"
  %"lo.p" = bitcast i8* %"lo.arg" to float*
  %"lo" = load float, float* %"lo.p", align 4
  %"result" = call <4 x float> @"clamp4"(<4 x float> %"v", float %"lo")
  %"ret.p" = bitcast i8* %"ret" to <4 x float>*
  store <4 x float> %"result", <4 x float>* %"ret.p", align 4
  ret void
}
