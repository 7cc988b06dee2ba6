define float @"relu_sum"(float* %"p", i32 %"n") nounwind
{
entry:
  %"i" = alloca i32
  %"acc" = alloca float
  br label %"body"
body:
  store float              0x0, float* %"acc"
  store i32 0, i32* %"i"
  br label %"for.cond"
for.cond:
  %"i.1" = load i32, i32* %"i"
  %"lt" = icmp slt i32 %"i.1", %"n"
  br i1 %"lt", label %"for.body", label %"for.end"
for.body:
  %"i.2" = load i32, i32* %"i"
  %"toindex" = sext i32 %"i.2" to i64
  %"addr" = getelementptr inbounds float, float* %"p", i64 %"toindex"
  %"load" = load float, float* %"addr", align 4
  %"gt" = fcmp ogt float %"load",              0x0
  br i1 %"gt", label %"if.then", label %"if.else"
for.next:
  %"i.3" = load i32, i32* %"i"
  %"i.next" = add i32 %"i.3", 1
  store i32 %"i.next", i32* %"i"
  br label %"for.cond"
for.end:
  %"acc.2" = load float, float* %"acc"
  ret float %"acc.2"
if.then:
  %"acc.1" = load float, float* %"acc"
  %"add" = fadd float %"acc.1", %"load"
  store float %"add", float* %"acc"
  br label %"if.end"
if.else:
  br label %"if.end"
if.end:
  br label %"for.next"
}

define void @"relu_sum.entry"(i8** %"argv", i8* %"ret") nounwind
{
entry:
  br label %"body"
body:
  %"p.argv" = getelementptr inbounds i8*, i8** %"argv", i64 0
  %"p.arg" = load i8*, i8** %"p.argv"
  %"p" = bitcast i8* %"p.arg" to float*
  %"n.argv" = getelementptr inbounds i8*, i8** %"argv", i64 1
  %"n.arg" = load i8*, i8** %"n.argv"
  %"n.p" = bitcast i8* %"n.arg" to i32*
  %"n" = load i32, i32* %"n.p", align 4
  %"result" = call float @"relu_sum"(float* %"p", i32 %"n")
  %"ret.p" = bitcast i8* %"ret" to float*
  store float %"result", float* %"ret.p", align 4
  ret void
}
