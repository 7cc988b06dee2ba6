define float @"axpy"(float %"a", float %"x", float %"y") nounwind
{
entry:
  br label %"body"
body:
  %"fma" = call float @"llvm.fma.f32"(float %"a", float %"x", float %"y")
  ret float %"fma"
}

declare float @"llvm.fma.f32"(float %".1", float %".2", float %".3")

define void @"axpy.entry"(i8** %"argv", i8* %"ret") nounwind
{
entry:
  br label %"body"
body:
  %"a.argv" = getelementptr inbounds i8*, i8** %"argv", i64 0
  %"a.arg" = load i8*, i8** %"a.argv"
  %"a.p" = bitcast i8* %"a.arg" to float*
  %"a" = load float, float* %"a.p", align 4
  %"x.argv" = getelementptr inbounds i8*, i8** %"argv", i64 1
  %"x.arg" = load i8*, i8** %"x.argv"
  %"x.p" = bitcast i8* %"x.arg" to float*
  %"x" = load float, float* %"x.p", align 4
  %"y.argv" = getelementptr inbounds i8*, i8** %"argv", i64 2
  %"y.arg" = load i8*, i8** %"y.argv"
  %"y.p" = bitcast i8* %"y.arg" to float*
  %"y" = load float, float* %"y.p", align 4
  %"result" = call float @"axpy"(float %"a", float %"x", float %"y")
  %"ret.p" = bitcast i8* %"ret" to float*
  store float %"result", float* %"ret.p", align 4
  ret void
}
